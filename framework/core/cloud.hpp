// SPDX-License-Identifier: MIT
// Point clouds owned by the host: built from disparity, handed to transforms as
// binocle_cloud views, written as binary PLY.
#pragma once

#include <binocle/abi/cloud_transform.h>

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace binocle {

struct StereoCalibration;

class Cloud {
public:
    std::vector<float> xyz;      // 3 per point, mm
    std::vector<uint8_t> rgb;    // 3 per point, or empty
    std::vector<int32_t> pixel;  // v * width + u of the left pixel
    int32_t image_width = 0, image_height = 0;
    int32_t frame = BINOCLE_FRAME_CAMERA;

    size_t size() const { return xyz.size() / 3; }
    // A view for plugins; the arrays are not reallocated by transforms.
    binocle_cloud view();
    // Takes the count (and frame) a transform left in the view.
    void adopt(const binocle_cloud &view);
};

// Triangulates every valid disparity (> 0) with the calibration's Q matrix, then turns
// the rectified frame back into the left camera's own frame (R1^T), so that the cloud
// is in METHOD.md's camera frame. Points farther than max_range_mm are dropped.
// `left` (GRAY8 or BGR8, may be empty) gives the colours.
Cloud cloudFromDisparity(const cv::Mat &disparity, const StereoCalibration &calibration, const cv::Mat &left,
                         double max_range_mm);

// The cloud stage of the runtime: the same points as cloudFromDisparity, computed
// straight from the disparity without an XYZ image. Q and R1^T are folded into
// per-column and per-disparity coefficients once, the row terms once per row, and only
// pixels with a valid disparity are visited; `out` keeps its storage from frame to frame.
class CloudProjector {
public:
    CloudProjector() = default;
    CloudProjector(const StereoCalibration &calibration, double max_range_mm);
    // Fills `out` (reusing its arrays) and returns the number of pixels with a disparity
    // > 0. `left` (GRAY8 or BGR8, may be empty) gives the colours.
    size_t project(const cv::Mat &disparity, const cv::Mat &left, Cloud &out) const;

private:
    // Five quantities per pixel: the three numerators of R1^T * (X, Y, Z), the
    // rectified Z numerator (for the range test) and W; each = row + u * col + d * disp.
    // Double precision: the terms cancel (u - cx), and the points must match the former
    // triangulation to float rounding.
    double col_[5] = {}, disp_[5] = {}, rowV_[5] = {}, row1_[5] = {};
    double maxRange_ = 0;
};

// Binary little-endian PLY with x, y, z (float, mm) and red, green, blue when present.
// The header's comments state the units and the frame. Written atomically.
void writePly(const std::string &path, const Cloud &cloud);
// Reads what writePly wrote (binary little-endian x y z [red green blue]).
Cloud readPly(const std::string &path);

} // namespace binocle
