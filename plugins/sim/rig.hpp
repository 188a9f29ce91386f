// SPDX-License-Identifier: MIT
// The simulated stereo head: pinhole imagers with Brown-Conrady distortion, the right
// imager's small misalignment, and the exact calibration that follows from them.
#pragma once

#include "scene.hpp"

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <array>
#include <string>

namespace binocle::sim {

using Vec2 = Eigen::Vector2d;
using Distortion = std::array<double, 5>; // k1, k2, p1, p2, k3 (OpenCV order)

struct RigSettings {
    int image_width = 320, image_height = 240;  // px
    double pixel_pitch_um = 20.8;                // effective pitch of an output pixel
    double focal_length_mm = 8;
    double baseline_mm = 150;
    double camera_height_mm = 1500;              // hc, optical centre above the ground
    double inclination_deg = 0;                  // theta, downward pitch (METHOD.md, Eq. 1)
    Distortion distortion{};                     // left imager
    Distortion distortion_right{};               // right imager
    Vec3 right_rotation_deg{0, 0, 0};            // roll (about Zc), pitch (Xc), yaw (Yc)
    Vec3 right_offset_mm{0, 0, 0};               // right optical centre minus (baseline, 0, 0), camera frame

    double focalLengthPx() const { return focal_length_mm * 1000.0 / pixel_pitch_um; }
    // True when the pair is ideal: no distortion, no misalignment.
    bool ideal() const;
};

// Where the rig stands in the scene: the ground frame of the current frame is the
// scene's frame shifted by this (the rig moves, the scene does not).
struct RigPose {
    double lateral_mm = 0; // along X
    double forward_mm = 0; // along Y
};

// A pinhole imager placed in the scene. Pixel centres are at integer coordinates.
struct Camera {
    int width = 0, height = 0;
    double fx = 1, fy = 1, cx = 0, cy = 0;
    Distortion distortion{};
    bool distorted = false;
    Mat3 rotation = Mat3::Identity(); // camera axes (Xc right, Yc down, Zc forward) -> ground axes
    Vec3 center{0, 0, 0};             // optical centre, ground frame of the scene

    // Direction (scene frame) of the ray that lands on pixel (u, v): rotation * (x, y, 1)
    // with (x, y) the undistorted normalised coordinates; ray() is it at unit length.
    Vec3 direction(double u, double v) const;
    Vec3 ray(double u, double v) const { return direction(u, v).normalized(); }
    // Pixel where a scene point lands; false when it is behind the imager.
    bool project(const Vec3 &point, double &u, double &v) const;
    // Brown-Conrady on normalised coordinates, and its inverse (Newton).
    Vec2 distort(const Vec2 &undistorted) const;
    Vec2 undistort(const Vec2 &distorted) const;
};

class StereoRig {
public:
    explicit StereoRig(const RigSettings &settings);

    const RigSettings &settings() const { return s_; }
    Camera left(const RigPose &pose) const;
    Camera right(const RigPose &pose) const;
    // The left imager after rectification with calibration(): the grid of the ground truth.
    Camera rectifiedLeft(const RigPose &pose) const;
    // Its partner: the right imager after rectification, the grid a matcher searches
    // (a point at disparity d in rectifiedLeft's pixel (u, v) lands on (u - d, v)).
    Camera rectifiedRight(const RigPose &pose) const;
    // Disparity of a point at depth z_mm (rectified left camera frame) in that grid.
    double rectifiedDisparity(double z_mm) const { return rectifiedFocalPx_ * rectifiedBaselineMm_ / z_mm + principalOffsetPx_; }

    // OpenCV FileStorage YAML in the format of framework/core/calibration.hpp.
    std::string calibrationYaml() const;

    // The calibration itself (CV_64F): x_r = R x_l + T, T in mm; R1 ... Q as
    // cv::stereoRectify(CALIB_ZERO_DISPARITY, alpha 0) gives them (identity when ideal).
    cv::Mat M1, D1, M2, D2, R, T, R1, R2, P1, P2, Q;

private:
    Camera camera(const RigPose &pose, const Mat3 &axesInLeft, const Vec3 &centreInLeft, const Distortion &d) const;

    RigSettings s_;
    Mat3 groundFromCamera_;  // Eq. 1 rotation
    Mat3 rightAxes_;         // right camera axes in the left camera frame
    Vec3 rightCentre_;       // right optical centre in the left camera frame
    double rectifiedFocalPx_ = 1, rectifiedBaselineMm_ = 1, principalOffsetPx_ = 0;
};

} // namespace binocle::sim
