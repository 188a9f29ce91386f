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
// pixels lie left of a foreground edge). Otherwise it is a mismatch. Hirschmueller treats
// mismatches next to occlusions as occlusions: a run is classified whole.
//
// A run that touches the left border (no valid pixel on its left: the band of columns
// whose match would lie left of the right image) takes the row's valid disparity on its
// right: there the diagonal and vertical directions run along the border through other
// such runs and bring values from far away (on the 19 shared pairs, bad-2 counting all
// pixels 10.2 % with the second lowest there, 9.2 % with this; plugins/sgm/README.md).
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
    // Down: each invalid pixel's values along the left direction and the three from above
    // (values 0 .. 3); up: the right direction and the three from below (4 .. 7).
    void gather(const cv::Mat &disparity, float invalid, bool down);
    void fillRow(float *row, uint8_t *filledRow, int y, float invalid, float occlusionJumpPx);

    int width_ = 0;
    // Per pass, the nearest valid disparity along each vertical or diagonal direction,
    // carried from row to row (previous, current), with a spare column at each end.
    std::vector<float> carry_[2][2][3];
    std::vector<int32_t> rowStart_;   // the first invalid pixel of each row, and the count
    std::vector<int32_t> column_;     // each invalid pixel's column
    std::vector<float> values_;       // kDirections values per invalid pixel
};

} // namespace sgm
