// SPDX-License-Identifier: MIT
// sgm: the per-row kernels of census + semi-global matching, one table per instruction set.
//
// Every kernel exists as a plain scalar reference (sgm_kernels_scalar.cpp) and as SIMD
// code written once with OpenCV's universal intrinsics (sgm_kernels_simd.inl), compiled
// for the compiler's baseline (SSE2 on x86-64, NEON on aarch64) and, on x86-64, for
// AVX2. The tables must agree bit for bit: tests/plugins_sgm checks it.
//
// Layouts shared by all kernels (D = num_disparities, Dp = D rounded up to the table's
// Kernels::dispAlign, a whole number of its vectors):
//  - cost row: width x Dp bytes, cost of pixel x at disparity d at [x * Dp + d];
//    d >= D and candidates left of the right image hold kCostInvalid;
//  - path row (L): width x (Dp + 2) bytes; pixel x's costs at [x * (Dp + 2) + 1 + d],
//    with a sentinel kCostInvalid at d = -1 and d = Dp so that the d - 1 and d + 1
//    neighbours are plain loads;
//  - sum row (S): width x Dp 16-bit sums of the path costs.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sgm {

// The helpers below are `static`: each file has its own copy, so the linker never hands
// a baseline caller the copy compiled for AVX2 (sgm_kernels_avx2.cpp includes this too).

// Disparity counts are padded to a multiple of a table's dispAlign: at least this (AVX2's
// 32 bytes, so that the scalar, baseline and AVX2 tables work on the same buffers), 64
// for the AVX-512 table (a whole 512-bit vector). Padded counts are at most kMaxPaddedDisp.
constexpr int kDispAlign = 32;
constexpr int kMaxPaddedDisp = 256;
constexpr uint8_t kCostInvalid = 255;

static inline int paddedDisparities(int numDisparities, int align = kDispAlign) {
    return (numDisparities + align - 1) / align * align;
}
static inline int pathStride(int paddedDisp) { return paddedDisp + 2; }
// Bytes of scratch the horizontal kernels take: two path rows, and the P2 of each pixel
// and its left neighbour for two rows.
static inline size_t horizontalScratch(int width, int paddedDisp) {
    return 2 * static_cast<size_t>(pathStride(paddedDisp)) + 2 * (static_cast<size_t>(width) + 1);
}

// Census bits of one row. rows[j] points at image column 0 of the grey row y + j - ch/2 of
// an image padded by cw/2 columns on each side (so rows[j][x + dx] is readable for
// |dx| <= cw/2). Full census (symmetric false): bit k of out[x] is set when neighbour k
// (row-major order in the cw x ch window, the centre skipped) is darker than the centre:
// cw * ch - 1 bits. Centre-symmetric census (symmetric true; Spangenberg et al. 2013):
// bit k is set when window pixel k (row-major, k before the centre) is darker than its
// mirror image about the centre, window pixel cw * ch - 1 - k: (cw * ch - 1) / 2 bits.
using CensusRowFn = void (*)(const uint8_t *const *rows, int width, int cw, int ch, bool symmetric, uint64_t *out);
static inline int censusBits(int cw, int ch, bool symmetric) {
    return symmetric ? (cw * ch - 1) / 2 : cw * ch - 1;
}

// Words of scratch costRow needs (the right census row rearranged for vector loads).
using CostScratchFn = size_t (*)(int width, int minDisparity, int paddedDisp);

// Hamming costs of one row: cost[x * Dp + d] = popcount(left[x] ^ right[x - minD - d]),
// kCostInvalid where x - minD - d < 0 or d >= numDisp.
using CostRowFn = void (*)(const uint64_t *left, const uint64_t *right, int width, int minDisparity, int numDisp,
                           int paddedDisp, uint64_t *scratch, uint8_t *cost);
// Words of census below 2^32 (a window of at most 32 bits) may take costRow32 instead: the
// same costs, counted on 32-bit lanes (twice the candidates a vector, half the popcounts);
// the same scratch.

// What one path direction needs besides the costs.
struct PathParams {
    int p1;               // penalty for a change of 1 px
    // Penalty for larger changes (>= p1) by the signed intensity step g = grey[x] -
    // grey[previous], -255..255, at p2ByStep[g]: 511 entries from p2ByStep - 255, the
    // same for g and -g (indexed by the difference itself: no absolute value per pixel).
    const uint8_t *p2ByStep;
};

// One row of up to kMaxRowPaths paths whose predecessors lie in the previous row
// (vertical or diagonal), all added to sum in one pass. Path i: pixel x follows pixel
// x + dx[i] of prevL[i] (dx in -1, 0, 1); a pixel without predecessor (prevL[i] NULL, or
// x + dx[i] outside) starts the path. grey/greyPrev: the intensities of this row and of
// the previous one, for the penalty P2. Writes curL[i] and curMin[i], and adds the
// row's path costs to sum (or stores them when initSum); sum NULL: no sum (a row whose
// paths are only carried on, or kept whole for a later pass).
constexpr int kMaxRowPaths = 3;
struct RowPaths {
    int count;
    int dx[kMaxRowPaths];
    const uint8_t *prevL[kMaxRowPaths];
    const uint8_t *prevMin[kMaxRowPaths];
    uint8_t *curL[kMaxRowPaths];
    uint8_t *curMin[kMaxRowPaths];
};
using PathRowFn = void (*)(const uint8_t *cost, int width, int paddedDisp, const RowPaths &paths, const uint8_t *grey,
                           const uint8_t *greyPrev, const PathParams &pp, uint16_t *sum, bool initSum);

// One row of both horizontal paths, left to right and right to left, added to sum (or
// stored, when initSum); scratch: horizontalScratch(width, paddedDisp) bytes.
using HorizontalRowFn = void (*)(const uint8_t *cost, int width, int paddedDisp, const uint8_t *grey,
                                 const PathParams &pp, uint8_t *scratch, uint16_t *sum, bool initSum);

// Both horizontal paths of `rows` rows (1 or 2, side by side: four serial chains whose
// latencies overlap), each stored whole as 8-bit path costs in the cost-row layout
// (width x paddedDisp bytes): forward[r] left to right, backward[r] right to left. The
// fused pass up of 4 paths adds them (upWtaRow). scratch: horizontalScratch(width,
// paddedDisp) bytes.
using HorizontalPathsFn = void (*)(const uint8_t *const *cost, int rows, int width, int paddedDisp,
                                   const uint8_t *const *grey, const PathParams &pp, uint8_t *scratch,
                                   uint8_t *const *forward, uint8_t *const *backward);

// Adds one stored path row (the path-row layout above) to a row of sums: the pass up of
// 4 paths adds the pass down's vertical path, kept as 8-bit costs.
using AddPathRowFn = void (*)(const uint8_t *pathRow, int width, int paddedDisp, uint16_t *sum);

// Winner takes all over one row of sums, d in [0, numDisp). For every pixel:
// best[x] = the lowest d of least sum (-1 where no candidate lies inside the right
// image), bestSum[x] that sum, and disparity16[x] = (minD + d) * 16 + sub-pixel part
// (parabola through the neighbours' sums, in 1/16 px), 0 where invalid: no candidate, or
// not unique (another d, away from best by more than 1, has sum * (100 - uniqueness) <
// bestSum * 100).
struct WtaParams {
    int minDisparity;
    int numDisp;
    int paddedDisp;
    int uniquenessPercent;
    bool subpixel;
};
using WtaRowFn = void (*)(const uint16_t *sum, int width, const WtaParams &wp, int16_t *best, uint16_t *bestSum,
                          uint16_t *disparity16);

// The pass up of 4 paths, the last kernel of a row, fused: the vertical path from below
// (as pathRow with paths.count == 1 and dx 0), whose costs are added to the row's
// horizontal paths (forward, backward: as horizontalPaths stores them, read only) and
// the pass down's kept vertical path (keptPath, as addPathRow), then the winner takes all
// over those sums (as wtaRow). A sum of four 8-bit paths is at most kMaxSum4: the SIMD
// tables find the winner by keys (sum << kWinnerKeyShift | d mod 64) that fit 16 bits.
constexpr int kMaxSum4 = 4 * 255;
constexpr int kWinnerKeyShift = 6;
static_assert(kMaxSum4 < (1 << (16 - kWinnerKeyShift)), "a key of a sum of 4 paths and d mod 64 fits 16 bits");
using UpWtaRowFn = void (*)(const uint8_t *cost, int width, int paddedDisp, const RowPaths &paths, const uint8_t *grey,
                            const uint8_t *greyPrev, const PathParams &pp, const uint8_t *keptPath,
                            const uint8_t *forward, const uint8_t *backward, const WtaParams &wp, int16_t *best,
                            uint16_t *bestSum, uint16_t *disparity16);

// The left-right check of a row, after its winners (best, bestSum as wtaRow leaves them):
// the right image's match of column xr is the left pixel of least (sum, d) that chose it
// (as OpenCV's SGBM derives it, from the same sums); disparity16[x] becomes 0 where best[x]
// differs from its right match's d by more than maxDiff (occluded or mismatched). rightKey:
// width + 1 words of scratch.
using LeftRightRowFn = void (*)(const int16_t *best, const uint16_t *bestSum, int width, int minDisparity, int maxDiff,
                                uint32_t *rightKey, uint16_t *disparity16);
// The first half of every table's check (scalar: pixels share right columns): per right
// column the least (sum, d) of the left pixels that chose it, as one key, the sum in the
// high half and d in the low, so that one minimum keeps the least sum and, among equal
// sums, the least d (the leftmost such pixel, the first one met). A pixel without
// candidate (d < 0, the left margin only) goes to the spare column `width`, which nothing
// reads: no branch a pixel.
static inline void rightColumnKeys(const int16_t *best, const uint16_t *bestSum, int width, int minDisparity,
                                   uint32_t *rightKey) {
    for (int x = 0; x <= width; ++x) rightKey[x] = UINT32_MAX;
    for (int x = 0; x < width; ++x) {
        const int d = best[x];
        const uint32_t key = static_cast<uint32_t>(bestSum[x]) << 16 | static_cast<uint16_t>(d);
        uint32_t &slot = rightKey[d < 0 ? width : x - minDisparity - d];
        slot = slot < key ? slot : key;
    }
}

// The median of the median_px x median_px window (size 1, 3 or 5) around each pixel of a
// row of disparities in 1/16 px (rows[0 .. size - 1]: the rows y - size / 2 .. y + size /
// 2, the caller repeating the image's first and last rows beyond it; the first and last
// columns are repeated likewise: OpenCV's medianBlur), converted to pixels: median / 16,
// or `invalid` where the median is 0. scratch: medianScratch(width) 16-bit words.
using MedianRowFn = void (*)(const uint16_t *const *rows, int width, int size, uint16_t *scratch, float invalid,
                             float *out);
constexpr int kMaxMedianPx = 5;
// Room for kMaxMedianPx rows of sorted columns, each with its border and a vector of slack.
static inline size_t medianScratch(int width) {
    return kMaxMedianPx * (static_cast<size_t>(width) + kMaxMedianPx + 64);
}

struct Kernels {
    const char *name;
    int dispAlign; // the padded disparity counts it takes are multiples of this
    CensusRowFn censusRow;
    CostScratchFn costScratchWords;
    CostRowFn costRow;
    CostRowFn costRow32; // census words < 2^32 only
    PathRowFn pathRow;
    HorizontalRowFn horizontalRow;
    HorizontalPathsFn horizontalPaths;
    AddPathRowFn addPathRow;
    WtaRowFn wtaRow;
    UpWtaRowFn upWtaRow;
    LeftRightRowFn leftRightRow;
    MedianRowFn medianRow;
};

const Kernels &scalarKernels();
// SIMD of the compiler's baseline; NULL when OpenCV has no universal intrinsics here.
const Kernels *baselineKernels();
// AVX2 (x86-64 only); NULL when not built in or when this CPU lacks AVX2.
const Kernels *avx2Kernels();
// AVX-512 (512-bit vectors, x86-64 only: F, BW, VL, DQ, CD, VBMI, VPOPCNTDQ and
// BITALG, as on Ice Lake, Zen 4 and later); NULL when not built in or when this CPU lacks
// one of them.
const Kernels *avx512Kernels();
// The fastest table this CPU runs.
const Kernels &bestKernels();

// The sub-pixel refinement shared by every table (scalar per pixel: no SIMD to compare).
// Returns (minD + d) * 16 + the parabola's offset in 1/16 px, or 0 when that is <= 0.
// The same from the sums at d - 1, d and d + 1 (left and right are read only for 0 < d <
// numDisp - 1).
static inline uint16_t refinedDisparity16(int left, int centre, int right, int d, const WtaParams &wp) {
    int value = (wp.minDisparity + d) * 16;
    if (wp.subpixel && d > 0 && d < wp.numDisp - 1) {
        const int denom = left + right - 2 * centre > 1 ? left + right - 2 * centre : 1;
        // Rounded to the nearest 1/16 px as OpenCV's SGBM does (truncating division of a
        // value offset by half the divisor).
        value += ((left - right) * 16 + denom) / (2 * denom);
    }
    return value > 0 ? static_cast<uint16_t>(value) : 0;
}
static inline uint16_t refinedDisparity16(const uint16_t *s, int d, const WtaParams &wp) {
    const bool inner = d > 0 && d < wp.numDisp - 1;
    return refinedDisparity16(inner ? s[d - 1] : 0, s[d], inner ? s[d + 1] : 0, d, wp);
}

} // namespace sgm
