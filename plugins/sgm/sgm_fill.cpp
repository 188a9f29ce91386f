// SPDX-License-Identifier: MIT
// sgm: the dense option (sgm_fill.hpp). The invalid pixels are listed; two passes over
// the image (in parallel) gather, for each of them, the nearest valid disparity along 8
// directions: the pass down on its left and from above, the pass up on its right and
// from below; then the rows are filled (in parallel). The vertical and diagonal directions
// are carried from row to row (a row of values each), so each pass reads every pixel once.
#include "sgm_fill.hpp"

#include <algorithm>
#include <limits>
#include <opencv2/core/hal/intrin.hpp>

namespace sgm {

namespace {

// The predecessor's column offset of the three directions carried from row to row:
// vertical, from the left diagonal, from the right diagonal.
constexpr int kCarryDx[3] = {0, -1, 1};

// A row's carried values: cur[x] = the pixel's own when valid, else what the direction
// brings from the previous row (prev[x + dx]); both rows have a spare column at each end.
// (OpenCV's universal intrinsics: a vector of floats at a time where the build has them.)
void carryRow(const float *row, int width, float invalid, const std::vector<float> (&prev)[3],
              std::vector<float> (&cur)[3]) {
    for (int d = 0; d < 3; ++d) {
        const float *p = prev[d].data() + 1 + kCarryDx[d];
        float *c = cur[d].data() + 1;
        int x = 0;
#if CV_SIMD
        const cv::v_float32 none = cv::vx_setall_f32(invalid);
        for (; x + cv::v_float32::nlanes <= width; x += cv::v_float32::nlanes) {
            const cv::v_float32 v = cv::vx_load(row + x);
            cv::v_store(c + x, cv::v_select(v != none, v, cv::vx_load(p + x)));
        }
#endif
        for (; x < width; ++x) c[x] = row[x] != invalid ? row[x] : p[x];
    }
}

// Appends the columns of the row's invalid pixels to `out`, in order (a vector of pixels
// compared at a time where the build has SIMD: most are valid).
void invalidColumns(const float *row, int width, float invalid, std::vector<int32_t> &out) {
    int x = 0;
#if CV_SIMD
    const cv::v_float32 none = cv::vx_setall_f32(invalid);
    for (; x + cv::v_float32::nlanes <= width; x += cv::v_float32::nlanes)
        for (int bits = cv::v_signmask(cv::vx_load(row + x) == none); bits; bits &= bits - 1)
            out.push_back(x + __builtin_ctz(static_cast<unsigned>(bits)));
#endif
    for (; x < width; ++x)
        if (row[x] == invalid) out.push_back(x);
}

// Sorts 8 values in place: a sorting network of 19 comparators (Knuth, TAOCP 5.3.4),
// branchless; absent values are +inf and end last.
void sort8(float *v) {
    static constexpr int kPairs[19][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3}, {4, 6}, {5, 7}, {1, 2}, {5, 6},
                                          {0, 4}, {3, 7}, {1, 5}, {2, 6}, {1, 4}, {3, 6}, {2, 4}, {3, 5}, {3, 4}};
    for (const auto &p : kPairs) {
        const float a = v[p[0]], b = v[p[1]];
        v[p[0]] = std::min(a, b);
        v[p[1]] = std::max(a, b);
    }
}

} // namespace

void Filler::fill(cv::Mat &disparity, float invalid, float occlusionJumpPx, cv::Mat &filled) {
    CV_Assert(disparity.type() == CV_32FC1);
    filled.create(disparity.size(), CV_8UC1);
    filled.setTo(cv::Scalar(0));
    if (disparity.empty()) return;
    width_ = disparity.cols;
    const int height = disparity.rows;
    // The invalid pixels, row by row.
    rowStart_.assign(static_cast<size_t>(height) + 1, 0);
    column_.clear();
    for (int y = 0; y < height; ++y) {
        rowStart_[static_cast<size_t>(y)] = static_cast<int32_t>(column_.size());
        invalidColumns(disparity.ptr<float>(y), width_, invalid, column_);
    }
    rowStart_[static_cast<size_t>(height)] = static_cast<int32_t>(column_.size());
    values_.resize(column_.size() * kDirections);
    // The two passes read the disparity only and write distinct values: in parallel;
    // then the rows are filled, in parallel too.
    cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range &r) {
        for (int pass = r.start; pass < r.end; ++pass) gather(disparity, invalid, pass == 0);
    });
    cv::parallel_for_(cv::Range(0, height), [&](const cv::Range &r) {
        for (int y = r.start; y < r.end; ++y)
            fillRow(disparity.ptr<float>(y), filled.ptr<uint8_t>(y), y, invalid, occlusionJumpPx);
    });
}

// Down: the left direction and the three from above (values 0 .. 3 of each invalid
// pixel); up: the right direction and the three from below (4 .. 7).
void Filler::gather(const cv::Mat &disparity, float invalid, bool down) {
    const int height = disparity.rows, step = down ? 1 : -1, side = down ? -1 : 1, slot = down ? 0 : 4;
    std::vector<float>(&carry)[2][3] = carry_[down ? 0 : 1];
    for (auto &rows : carry)
        for (auto &row : rows) row.assign(static_cast<size_t>(width_) + 2, invalid);
    int parity = 0;
    for (int y = down ? 0 : height - 1; y >= 0 && y < height; y += step) {
        const float *row = disparity.ptr<float>(y);
        carryRow(row, width_, invalid, carry[parity ^ 1], carry[parity]);
        const std::vector<float>(&cur)[3] = carry[parity];
        const int32_t first = rowStart_[static_cast<size_t>(y)], end = rowStart_[static_cast<size_t>(y) + 1];
        // The row's direction, its invalid pixels walked from that side: the pixel's
        // neighbour on that side when valid, else (within a run) what the run's pixel
        // before it has; nothing at the border.
        float along = invalid;
        for (int32_t i = 0; i < end - first; ++i) {
            const size_t k = static_cast<size_t>(down ? first + i : end - 1 - i);
            const int x = column_[k], n = x + side;
            if (n < 0 || n >= width_) along = invalid;
            else if (row[n] != invalid) along = row[n];
            float *v = values_.data() + k * kDirections + slot;
            const size_t at = static_cast<size_t>(x) + 1;
            v[0] = along;
            v[1] = cur[0][at];
            v[2] = cur[1][at];
            v[3] = cur[2][at];
        }
        parity ^= 1;
    }
}

// Row y's invalid pixels, run by run: an occlusion takes the second lowest of its
// directions' values, a mismatch their median, a run at the left border the row's
// value on its right (sgm_fill.hpp).
void Filler::fillRow(float *row, uint8_t *filledRow, int y, float invalid, float occlusionJumpPx) {
    const int32_t first = rowStart_[static_cast<size_t>(y)], end = rowStart_[static_cast<size_t>(y) + 1];
    bool occluded = false;
    for (int32_t k = first; k < end; ++k) {
        const float *v = values_.data() + static_cast<size_t>(k) * kDirections;
        const int x = column_[static_cast<size_t>(k)];
        // A run starts where the previous invalid pixel is not the left neighbour; all its
        // pixels share the valid values on its left (v[0]) and right (v[4]).
        if (k == first || column_[static_cast<size_t>(k) - 1] != x - 1)
            occluded = v[0] == invalid || (v[4] != invalid && v[4] > v[0] + occlusionJumpPx);
        float found[kDirections];
        int n = 0;
        for (int d = 0; d < kDirections; ++d) {
            const bool valid = v[d] != invalid;
            found[d] = valid ? v[d] : std::numeric_limits<float>::infinity();
            n += valid;
        }
        if (n == 0) continue; // nothing valid in any direction: stays invalid
        sort8(found);
        if (v[0] == invalid && v[4] != invalid) row[x] = v[4]; // the left border: the row's value on its right
        else if (occluded) row[x] = found[n > 1 ? 1 : 0];
        else row[x] = n % 2 ? found[n / 2] : 0.5f * (found[n / 2 - 1] + found[n / 2]);
        filledRow[x] = 255;
    }
}

} // namespace sgm
