// SPDX-License-Identifier: MIT
// sgm: the dense option (sgm_fill.hpp). Two passes over the image: the pass down gathers,
// for each invalid pixel, the nearest valid disparity on its left and along the three
// directions from above; the pass up those on its right and from below, then fills the
// row. The vertical and diagonal directions are carried from row to row (a row of values
// each), so each pass reads every pixel once.
#include "sgm_fill.hpp"

#include <algorithm>

namespace sgm {

namespace {

// The predecessor's column offset of the three directions carried from row to row:
// vertical, from the left diagonal, from the right diagonal.
constexpr int kCarryDx[3] = {0, -1, 1};

// A row's carried values: cur[x] = the pixel's own when valid, else what the direction
// brings from the previous row (prev[x + dx]); both rows have a spare column at each end.
void carryRow(const float *row, int width, float invalid, const std::vector<float> (&prev)[3],
              std::vector<float> (&cur)[3]) {
    for (int d = 0; d < 3; ++d) {
        const float *p = prev[d].data() + 1 + kCarryDx[d];
        float *c = cur[d].data() + 1;
        for (int x = 0; x < width; ++x) c[x] = row[x] != invalid ? row[x] : p[x];
    }
}

// Sorts the n (<= 8) values in place (insertion sort: a handful of values).
void sortSmall(float *v, int n) {
    for (int i = 1; i < n; ++i) {
        const float key = v[i];
        int j = i - 1;
        for (; j >= 0 && v[j] > key; --j) v[j + 1] = v[j];
        v[j + 1] = key;
    }
}

} // namespace

void Filler::fill(cv::Mat &disparity, float invalid, float occlusionJumpPx, cv::Mat &filled) {
    CV_Assert(disparity.type() == CV_32FC1);
    filled.create(disparity.size(), CV_8UC1);
    filled.setTo(cv::Scalar(0));
    if (disparity.empty()) return;
    width_ = disparity.cols;
    for (auto &rows : carry_)
        for (auto &row : rows) row.assign(static_cast<size_t>(width_) + 2, invalid);
    passDown(disparity, invalid);
    for (auto &rows : carry_)
        for (auto &row : rows) std::fill(row.begin(), row.end(), invalid);
    passUp(disparity, invalid, occlusionJumpPx, filled);
}

void Filler::passDown(const cv::Mat &disparity, float invalid) {
    const int height = disparity.rows;
    rowStart_.assign(static_cast<size_t>(height) + 1, 0);
    column_.clear();
    values_.clear();
    int parity = 0;
    for (int y = 0; y < height; ++y) {
        const float *row = disparity.ptr<float>(y);
        carryRow(row, width_, invalid, carry_[parity ^ 1], carry_[parity]);
        const std::vector<float>(&cur)[3] = carry_[parity];
        rowStart_[static_cast<size_t>(y)] = static_cast<int32_t>(column_.size());
        float left = invalid;
        for (int x = 0; x < width_; ++x) {
            if (row[x] != invalid) {
                left = row[x];
                continue;
            }
            column_.push_back(x);
            const size_t at = static_cast<size_t>(x) + 1;
            values_.insert(values_.end(), {left, cur[0][at], cur[1][at], cur[2][at], invalid, invalid, invalid, invalid});
        }
        parity ^= 1;
    }
    rowStart_[static_cast<size_t>(height)] = static_cast<int32_t>(column_.size());
}

void Filler::passUp(cv::Mat &disparity, float invalid, float occlusionJumpPx, cv::Mat &filled) {
    int parity = 0;
    for (int y = disparity.rows - 1; y >= 0; --y) {
        float *row = disparity.ptr<float>(y);
        carryRow(row, width_, invalid, carry_[parity ^ 1], carry_[parity]);
        const std::vector<float>(&cur)[3] = carry_[parity];
        const int32_t first = rowStart_[static_cast<size_t>(y)], end = rowStart_[static_cast<size_t>(y) + 1];
        // The right direction, walking the row's invalid pixels backwards with the row.
        float right = invalid;
        int32_t k = end - 1;
        for (int x = width_ - 1; x >= 0 && k >= first; --x) {
            if (row[x] != invalid) {
                right = row[x];
                continue;
            }
            float *v = values_.data() + static_cast<size_t>(k) * kDirections;
            const size_t at = static_cast<size_t>(x) + 1;
            v[4] = right;
            v[5] = cur[0][at];
            v[6] = cur[1][at];
            v[7] = cur[2][at];
            --k;
        }
        fillRow(row, filled.ptr<uint8_t>(y), y, invalid, occlusionJumpPx);
        parity ^= 1;
    }
}

// Row y's invalid pixels, run by run: an occlusion takes the second lowest of its
// directions' values, a mismatch their median (sgm_fill.hpp).
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
        for (int d = 0; d < kDirections; ++d)
            if (v[d] != invalid) found[n++] = v[d];
        if (n == 0) continue; // nothing valid in any direction: stays invalid
        sortSmall(found, n);
        if (occluded) row[x] = found[n > 1 ? 1 : 0];
        else row[x] = n % 2 ? found[n / 2] : 0.5f * (found[n / 2 - 1] + found[n / 2]);
        filledRow[x] = 255;
    }
}

} // namespace sgm
