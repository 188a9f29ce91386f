// SPDX-License-Identifier: MIT
// The oracle cloud: what the camera configuration alone allows. The frame's ground-truth
// disparity (`gt_disparity`, which the sim source attaches in the rectified left grid)
// reprojected with the same calibration (Q, R1) and moved into the ground frame with
// the same Eq. 1 pose as the matcher's cloud, so that the same reading on both separates
// what the lens and baseline cost from what the matcher costs.
#pragma once

#include <binocle/abi.h>

#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <vector>

namespace binocle::paper {

class OracleProjector {
public:
    // Parses Q and R1 from the calibration YAML (OpenCV FileStorage text); an empty or
    // unreadable text, or one without Q, gives an unusable projector (usable() false).
    void setCalibration(const std::string &calibration_yaml);
    bool usable() const { return usable_; }

    // The ground-frame cloud (X, Y, Z mm interleaved) of the frame's gt_disparity extra,
    // with Eq. 1 at camera height hc and inclination theta; nullopt when the frame has no
    // FLOAT32 gt_disparity or the projector is unusable.
    std::optional<std::vector<float>> groundCloud(const binocle_stereo_frame *frame, double camera_height_mm,
                                                  double inclination_deg) const;

private:
    bool usable_ = false;
    cv::Matx44d Q_;
    cv::Matx33d R1t_ = cv::Matx33d::eye();
};

} // namespace binocle::paper
