// SPDX-License-Identifier: MIT
// sgm: the dense option. Fills the pixels the checks left invalid as Hirschmueller
// describes (PAMI 2008, "Stereo processing by semiglobal matching and mutual
// information", section 3.5, discontinuity preserving interpolation): each invalid pixel
// is classified as an occlusion or a mismatch; the nearest valid disparities along 8
// directions are gathered; an occlusion takes the second lowest of them (the background:
// an occluded pixel must not take the occluder's disparity, and the second lowest is more
// robust against outliers than the lowest), a mismatch their median.
//
// Classification (the epipolar-line test of section 3.5, on the left image): along a row,
// a run of invalid pixels between the valid disparities dl (left of it) and dr (right of
// it) is an occlusion when dr > dl + occlusion_jump_px: the surface on its right is in
// front and hides the background from the right camera (in the left image the occluded
// pixels lie left of a foreground edge), or when the run touches the left border (no
// valid pixel on its left: a background the right camera does not see). Otherwise it is a
// mismatch. Hirschmueller treats mismatches next to occlusions as occlusions: a run is
// classified whole.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace sgm {

class Filler {
public:
    // disparity: CV_32FC1, `invalid` where no match survived; every such pixel that has
    // a valid disparity along one of the 8 directions gets one. filled: CV_8UC1 of the
    // same size, made here: 255 where a value was filled in, 0 elsewhere.
    void fill(cv::Mat &disparity, float invalid, float occlusionJumpPx, cv::Mat &filled);

private:
    static constexpr int kDirections = 8;
    // Pass down: the left, up, up-left and up-right directions; pass up: right, down,
    // down-left and down-right. Values of the invalid pixels, in scan order.
    void passDown(const cv::Mat &disparity, float invalid);
    void passUp(cv::Mat &disparity, float invalid, float occlusionJumpPx, cv::Mat &filled);
    void fillRow(float *row, uint8_t *filledRow, int y, float invalid, float occlusionJumpPx);

    int width_ = 0;
    // The nearest valid disparity along each vertical or diagonal direction, carried from
    // row to row (previous, current), with a spare column at each end (`invalid`).
    std::vector<float> carry_[2][3];
    std::vector<int32_t> rowStart_;   // the first invalid pixel of each row, and the count
    std::vector<int32_t> column_;     // each invalid pixel's column
    std::vector<float> values_;       // kDirections values per invalid pixel
};

} // namespace sgm
