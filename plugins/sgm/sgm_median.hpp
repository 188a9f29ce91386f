// SPDX-License-Identifier: MIT
// sgm: the comparator networks of the median filter on the disparity (median_px 3 and 5).
//
// A window of k x k pixels is k*k wires, wire r * k + c holding row r, column c. First
// each column is sorted (kSort3 / kSort5 on its k wires, top to bottom): a SIMD table
// sorts every column of a row once and each window reads its k sorted columns, so the
// neighbours share that work. Then kMedianOf9 / kMedianOf25 leave the median on wire
// k*k / 2. They were derived by machine: the column sorts, the row sorts, then Batcher's
// odd-even merge sort of all k*k wires; every comparator that never exchanges (tested on
// all 2^(k*k) inputs of 0s and 1s, after the comparators before it) removed; then every
// comparator the median's wire does not depend on, and of the rest only the outputs used.
// By the 0-1 principle a network that selects the median of every 0-1 input selects it
// of every input: tests/plugins_sgm checks this on all 2^25 and 2^9 such inputs.
#pragma once

#include <cstdint>

namespace sgm {

// Wires i < j: the least of the two goes to i, the greatest to j. keep: bit 0, wire i's
// result is used later; bit 1, wire j's (a comparator whose one result is unused costs
// one instruction instead of two).
struct MedianComparator {
    uint8_t i, j, keep;
};

// Sorting networks of 3 and 5 wires (3 and 9 comparators, both results used).
constexpr uint8_t kSort3[][2] = {{0, 1}, {1, 2}, {0, 1}};
constexpr uint8_t kSort5[][2] = {{0, 1}, {3, 4}, {2, 4}, {2, 3}, {0, 3}, {0, 2}, {1, 4}, {1, 3}, {1, 2}};

// 3x3: 17 comparators after the columns are sorted (26 min/max)
constexpr MedianComparator kMedianOf9[] = {
    {0, 1, 3}, {1, 2, 3}, {0, 1, 2}, {3, 4, 3}, {4, 5, 3}, {3, 4, 3}, {6, 7, 3}, {7, 8, 1}, {6, 7, 3},
    {2, 3, 3}, {4, 6, 3}, {5, 7, 1}, {1, 2, 2}, {5, 6, 1}, {2, 4, 2}, {3, 5, 1}, {3, 4, 2},
};
// 5x5: 93 comparators after the columns are sorted (162 min/max)
constexpr MedianComparator kMedianOf25[] = {
    {0, 1, 3}, {3, 4, 3}, {2, 4, 3}, {2, 3, 3}, {0, 3, 3}, {0, 2, 2}, {1, 4, 3}, {1, 3, 3}, {1, 2, 2},
    {5, 6, 3}, {8, 9, 3}, {7, 9, 3}, {7, 8, 3}, {5, 8, 3}, {5, 7, 3}, {6, 9, 3}, {6, 8, 3}, {6, 7, 3},
    {10, 11, 3}, {13, 14, 3}, {12, 14, 3}, {12, 13, 3}, {10, 13, 3}, {10, 12, 3}, {11, 14, 3}, {11, 13, 3},
    {11, 12, 3}, {15, 16, 3}, {18, 19, 3}, {17, 19, 3}, {17, 18, 3}, {15, 18, 3}, {15, 17, 3}, {16, 19, 3},
    {16, 18, 3}, {16, 17, 3}, {20, 21, 3}, {23, 24, 3}, {22, 24, 3}, {22, 23, 3}, {20, 23, 3}, {20, 22, 3},
    {21, 24, 1}, {21, 23, 3}, {21, 22, 3}, {4, 5, 3}, {14, 15, 1}, {5, 7, 3}, {8, 10, 3}, {9, 11, 3},
    {12, 14, 3}, {5, 6, 3}, {9, 10, 3}, {13, 14, 3}, {16, 20, 3}, {17, 21, 3}, {18, 22, 3}, {19, 23, 1},
    {2, 4, 2}, {3, 5, 3}, {10, 12, 3}, {11, 13, 3}, {18, 20, 3}, {19, 21, 3}, {3, 4, 2}, {5, 6, 3},
    {9, 10, 3}, {11, 12, 3}, {13, 14, 1}, {17, 18, 3}, {19, 20, 3}, {21, 22, 1}, {4, 8, 2}, {5, 9, 2},
    {6, 10, 3}, {7, 11, 3}, {6, 8, 2}, {7, 9, 3}, {11, 13, 3}, {7, 8, 2}, {9, 10, 3}, {11, 12, 3}, {8, 16, 2},
    {9, 17, 2}, {10, 18, 1}, {11, 19, 1}, {12, 20, 1}, {13, 21, 1}, {12, 16, 1}, {13, 17, 1}, {10, 12, 2},
    {11, 13, 1}, {11, 12, 2},
};

} // namespace sgm
