// SPDX-License-Identifier: MIT
// The oracle cloud from the frame's ground-truth disparity (oracle_cloud.hpp).
#include "paper/oracle_cloud.hpp"

#include "method/ground_frame.hpp"

#include <cmath>
#include <cstring>

namespace binocle::paper {

void OracleProjector::setCalibration(const std::string &text) {
    usable_ = false;
    if (text.empty()) return;
    try {
        cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
        cv::Mat q, r1;
        fs["Q"] >> q;
        fs["R1"] >> r1;
        if (q.rows != 4 || q.cols != 4) return;
        q.convertTo(q, CV_64F);
        Q_ = cv::Matx44d(q.ptr<double>());
        R1t_ = cv::Matx33d::eye();
        if (r1.rows == 3 && r1.cols == 3) {
            r1.convertTo(r1, CV_64F);
            R1t_ = cv::Matx33d(r1.ptr<double>()).t();
        }
        usable_ = true;
    } catch (const cv::Exception &) {
        usable_ = false; // no oracle: the matcher's figures are still reported
    }
}

std::optional<std::vector<float>> OracleProjector::groundCloud(const binocle_stereo_frame *frame, double hc,
                                                               double theta) const {
    if (!usable_ || !frame) return std::nullopt;
    const binocle_image *gt = nullptr;
    for (int32_t i = 0; i < frame->extra_count; ++i)
        if (frame->extras[i].name && std::strcmp(frame->extras[i].name, "gt_disparity") == 0 &&
            frame->extras[i].image.format == BINOCLE_PIXEL_FLOAT32)
            gt = &frame->extras[i].image;
    if (!gt || !gt->data) return std::nullopt;
    const method::GroundFrame eq1(hc, theta);
    std::vector<float> xyz;
    xyz.reserve(static_cast<size_t>(gt->width) * gt->height * 3);
    for (int v = 0; v < gt->height; ++v) {
        const auto *row = reinterpret_cast<const float *>(static_cast<const uint8_t *>(gt->data) +
                                                          static_cast<size_t>(v) * gt->stride_bytes);
        for (int u = 0; u < gt->width; ++u) {
            const double d = row[u];
            if (!(d > 0) || !std::isfinite(d)) continue; // unknown (sky)
            const cv::Vec4d h = Q_ * cv::Vec4d(u, v, d, 1);
            if (!(h[3] > 0)) continue;
            // Rectified left frame, then the left camera's own frame (as the pipeline's cloud).
            const cv::Vec3d c = R1t_ * cv::Vec3d(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
            if (!(c[2] > 0)) continue;
            const auto g = eq1.toGround(c[0], c[1], c[2]);
            xyz.push_back(static_cast<float>(g[0]));
            xyz.push_back(static_cast<float>(g[1]));
            xyz.push_back(static_cast<float>(g[2]));
        }
    }
    return xyz;
}

} // namespace binocle::paper
