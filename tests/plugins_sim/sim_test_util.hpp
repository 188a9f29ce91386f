// SPDX-License-Identifier: MIT
// Helpers of the sim tests: a misaligned head, marker scenes, Eq. 1 written out
// independently of the renderer, and blob centroids.
#pragma once

#include "renderer.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace binocle::test {

// Ground frame -> camera frame (inverse of METHOD.md Eq. 1), written here from the
// equation rather than taken from the renderer, so that the tests check the renderer.
inline cv::Point3d groundToCamera(const cv::Point3d &g, double cameraHeightMm, double inclinationDeg) {
    const double th = inclinationDeg * CV_PI / 180.0;
    const double a = g.y, b = cameraHeightMm - g.z; // Y = Zc cos - Yc sin; hc - Z = Zc sin + Yc cos
    return {g.x, -a * std::sin(th) + b * std::cos(th), a * std::cos(th) + b * std::sin(th)};
}

// The misaligned, distorted, inclined head of the calibration and occlusion tests.
inline sim::RigSettings imperfectRig() {
    sim::RigSettings s;
    s.inclination_deg = 5;
    s.distortion = {-0.12, 0.04, 0.0008, -0.0006, 0};
    s.distortion_right = {-0.10, 0.03, -0.0005, 0.0007, 0};
    s.right_rotation_deg = sim::Vec3(0.6, -0.5, 0.8);
    s.right_offset_mm = sim::Vec3(1.5, -2.0, 3.0);
    return s;
}

// A black world (no ground, black sky) with small bright squares facing the rig, their
// faces centred on `centres` (ground frame, mm); `sideMm` wide, 2 mm thick.
inline sim::Scene markerScene(const std::vector<cv::Point3d> &centres, double sideMm) {
    sim::Scene scene;
    scene.name = "markers";
    scene.groundTexture = -1;
    scene.sky.zenith = scene.sky.horizon = sim::Rgb::Zero();
    scene.light.ambient = 1.0; // every face equally bright, whatever its normal
    sim::Texture white;
    white.color0 = sim::Rgb::Ones();
    const int texture = scene.addTexture(white);
    for (size_t i = 0; i < centres.size(); ++i) {
        sim::Primitive p;
        p.shape = sim::Shape::Box;
        p.half = sim::Vec3(sideMm / 2, 1.0, sideMm / 2);
        p.center = sim::Vec3(centres[i].x, centres[i].y + 1.0, centres[i].z); // front face at y
        p.texture.fill(texture);
        scene.addObject("marker" + std::to_string(i), "box", {p});
    }
    return scene;
}

// Intensity-weighted centroid of the pixels within `radius` of `around`.
inline cv::Point2d centroidNear(const cv::Mat &grey, const cv::Point2d &around, int radius) {
    double sum = 0, sx = 0, sy = 0;
    for (int v = std::max(0, static_cast<int>(around.y) - radius); v <= std::min(grey.rows - 1, static_cast<int>(around.y) + radius); ++v)
        for (int u = std::max(0, static_cast<int>(around.x) - radius); u <= std::min(grey.cols - 1, static_cast<int>(around.x) + radius); ++u) {
            const double w = grey.type() == CV_8U ? grey.at<uint8_t>(v, u) : grey.at<float>(v, u);
            sum += w;
            sx += w * u;
            sy += w * v;
        }
    return sum > 0 ? cv::Point2d(sx / sum, sy / sum) : cv::Point2d(-1, -1);
}

} // namespace binocle::test
