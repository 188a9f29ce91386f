// SPDX-License-Identifier: MIT
// sgm: the scalar reference of every kernel: the plainest code that states what the SIMD
// versions must compute, bit for bit (8-bit path costs saturate exactly as theirs do).
#include "sgm_kernels.hpp"

#include <algorithm>
#include <cstdlib>
#include <iterator>
#include <vector>

namespace sgm {
namespace {

inline uint8_t addSat(int a, int b) { return static_cast<uint8_t>(std::min(255, a + b)); }
inline uint8_t subSat(int a, int b) { return static_cast<uint8_t>(std::max(0, a - b)); }

void censusRowScalar(const uint8_t *const *rows, int width, int cw, int ch, bool symmetric, uint64_t *out) {
    const int rx = cw / 2, ry = ch / 2;
    if (symmetric) {
        const int bits = censusBits(cw, ch, true), last = cw * ch - 1;
        for (int x = 0; x < width; ++x) {
            uint64_t word = 0;
            for (int k = 0; k < bits; ++k) {
                const int mirror = last - k;
                const uint8_t a = rows[k / cw][x + k % cw - rx], b = rows[mirror / cw][x + mirror % cw - rx];
                word |= static_cast<uint64_t>(a < b) << k;
            }
            out[x] = word;
        }
        return;
    }
    for (int x = 0; x < width; ++x) {
        const uint8_t centre = rows[ry][x];
        uint64_t bits = 0;
        int k = 0;
        for (int j = 0; j < ch; ++j)
            for (int dx = -rx; dx <= rx; ++dx) {
                if (j == ry && dx == 0) continue;
                bits |= static_cast<uint64_t>(rows[j][x + dx] < centre) << k;
                ++k;
            }
        out[x] = bits;
    }
}

size_t costScratchScalar(int, int, int) { return 0; }

void costRowScalar(const uint64_t *left, const uint64_t *right, int width, int minD, int numDisp, int paddedDisp,
                   uint64_t *, uint8_t *cost) {
    for (int x = 0; x < width; ++x)
        for (int d = 0; d < paddedDisp; ++d) {
            const int xr = x - minD - d;
            cost[static_cast<size_t>(x) * paddedDisp + d] =
                d < numDisp && xr >= 0 ? static_cast<uint8_t>(__builtin_popcountll(left[x] ^ right[xr])) : kCostInvalid;
        }
}

// L(p, d) = C(p, d) + min(L(q, d), L(q, d +- 1) + P1, min L(q) + P2) - min L(q), q the
// predecessor, all in saturating 8-bit arithmetic. Adds L to sum; returns min L(p).
uint8_t pathStep(const uint8_t *cost, const uint8_t *prev, int minPrev, int p1, int p2, uint8_t *out, uint16_t *sum,
                 int paddedDisp, bool initSum) {
    const uint8_t jump = addSat(minPrev, p2);
    uint8_t least = 255;
    for (int d = 0; d < paddedDisp; ++d) {
        uint8_t t = std::min(prev[d], addSat(std::min(prev[d - 1], prev[d + 1]), p1));
        t = std::min(t, jump);
        const uint8_t l = addSat(cost[d], subSat(t, minPrev));
        out[d] = l;
        least = std::min(least, l);
        if (sum) sum[d] = static_cast<uint16_t>(initSum ? l : std::min(65535, sum[d] + l));
    }
    return least;
}

// A predecessor that is not there: every cost at the sentinel, so that L = C.
struct Fresh {
    uint8_t data[kMaxPaddedDisp + 2];
    Fresh() { std::fill(std::begin(data), std::end(data), kCostInvalid); }
};
const uint8_t *freshPath() {
    static const Fresh fresh;
    return fresh.data + 1;
}

void pathRowScalar(const uint8_t *cost, int width, int paddedDisp, const RowPaths &paths, const uint8_t *grey,
                   const uint8_t *greyPrev, const PathParams &pp, uint16_t *sum, bool initSum) {
    const int stride = pathStride(paddedDisp);
    for (int i = 0; i < paths.count; ++i)
        for (int x = 0; x < width; ++x) {
            const int xp = x + paths.dx[i];
            const bool has = paths.prevL[i] && xp >= 0 && xp < width;
            const uint8_t *prev = has ? paths.prevL[i] + static_cast<size_t>(xp) * stride + 1 : freshPath();
            const int minPrev = has ? paths.prevMin[i][xp] : 255;
            const int p2 = has ? pp.p2ByStep[grey[x] - greyPrev[xp]] : pp.p2ByStep[0];
            paths.curMin[i][x] = pathStep(cost + static_cast<size_t>(x) * paddedDisp, prev, minPrev, pp.p1, p2,
                                          paths.curL[i] + static_cast<size_t>(x) * stride + 1,
                                          sum ? sum + static_cast<size_t>(x) * paddedDisp : nullptr, paddedDisp,
                                          initSum && i == 0);
        }
}

// One horizontal path of a row, added to sum (or stored, when initSum; sum NULL: none);
// path: each pixel's path costs too, in the cost-row layout (NULL: not kept).
void horizontalPath(const uint8_t *cost, int width, int paddedDisp, bool forward, const uint8_t *grey,
                    const PathParams &pp, uint8_t *scratch, uint16_t *sum, bool initSum, uint8_t *path = nullptr) {
    const int stride = pathStride(paddedDisp);
    uint8_t *bufs[2] = {scratch + 1, scratch + stride + 1};
    const uint8_t *prev = freshPath();
    int minPrev = 255, previousX = -1;
    for (int i = 0; i < width; ++i) {
        const int x = forward ? i : width - 1 - i;
        const int p2 = previousX < 0 ? pp.p2ByStep[0] : pp.p2ByStep[grey[x] - grey[previousX]];
        uint8_t *out = bufs[i & 1];
        minPrev = pathStep(cost + static_cast<size_t>(x) * paddedDisp, prev, minPrev, pp.p1, p2, out,
                           sum ? sum + static_cast<size_t>(x) * paddedDisp : nullptr, paddedDisp, initSum);
        if (path) std::copy(out, out + paddedDisp, path + static_cast<size_t>(x) * paddedDisp);
        prev = out;
        previousX = x;
    }
}

void horizontalRowScalar(const uint8_t *cost, int width, int paddedDisp, const uint8_t *grey, const PathParams &pp,
                         uint8_t *scratch, uint16_t *sum, bool initSum) {
    horizontalPath(cost, width, paddedDisp, false, grey, pp, scratch, sum, initSum);
    horizontalPath(cost, width, paddedDisp, true, grey, pp, scratch, sum, false);
}

void horizontalPathsScalar(const uint8_t *const *cost, int rows, int width, int paddedDisp, const uint8_t *const *grey,
                           const PathParams &pp, uint8_t *scratch, uint8_t *const *forward, uint8_t *const *backward) {
    for (int r = 0; r < rows; ++r) {
        horizontalPath(cost[r], width, paddedDisp, true, grey[r], pp, scratch, nullptr, false, forward[r]);
        horizontalPath(cost[r], width, paddedDisp, false, grey[r], pp, scratch, nullptr, false, backward[r]);
    }
}

void addPathRowScalar(const uint8_t *pathRow, int width, int paddedDisp, uint16_t *sum) {
    const int stride = pathStride(paddedDisp);
    for (int x = 0; x < width; ++x)
        for (int d = 0; d < paddedDisp; ++d) {
            uint16_t &s = sum[static_cast<size_t>(x) * paddedDisp + d];
            s = static_cast<uint16_t>(std::min(65535, s + pathRow[static_cast<size_t>(x) * stride + 1 + d]));
        }
}

void wtaRowScalar(const uint16_t *sum, int width, const WtaParams &wp, int16_t *best, uint16_t *bestSum,
                  uint16_t *disparity16) {
    for (int x = 0; x < width; ++x) {
        const uint16_t *s = sum + static_cast<size_t>(x) * wp.paddedDisp;
        int b = 0;
        for (int d = 1; d < wp.numDisp; ++d)
            if (s[d] < s[b]) b = d;
        bestSum[x] = s[b];
        if (x - wp.minDisparity - b < 0) {
            best[x] = -1;
            disparity16[x] = 0;
            continue;
        }
        best[x] = static_cast<int16_t>(b);
        bool unique = true;
        for (int d = 0; d < wp.numDisp && unique; ++d)
            if (std::abs(d - b) > 1 && s[d] * (100 - wp.uniquenessPercent) < s[b] * 100) unique = false;
        disparity16[x] = unique ? refinedDisparity16(s, b, wp) : 0;
    }
}

// The kernels it fuses, one after the other: the horizontal paths' sums, the path from
// below added, the kept path added, the winners.
void upWtaRowScalar(const uint8_t *cost, int width, int paddedDisp, const RowPaths &paths, const uint8_t *grey,
                    const uint8_t *greyPrev, const PathParams &pp, const uint8_t *keptPath, const uint8_t *forward,
                    const uint8_t *backward, const WtaParams &wp, int16_t *best, uint16_t *bestSum,
                    uint16_t *disparity16) {
    thread_local std::vector<uint16_t> sums; // grows once: no allocation per frame after the first
    sums.resize(static_cast<size_t>(width) * paddedDisp);
    for (size_t i = 0; i < sums.size(); ++i) sums[i] = static_cast<uint16_t>(forward[i] + backward[i]);
    pathRowScalar(cost, width, paddedDisp, paths, grey, greyPrev, pp, sums.data(), false);
    addPathRowScalar(keptPath, width, paddedDisp, sums.data());
    wtaRowScalar(sums.data(), width, wp, best, bestSum, disparity16);
}

void leftRightRowScalar(const int16_t *best, const uint16_t *bestSum, int width, int minD, int maxDiff,
                        uint32_t *rightKey, uint16_t *disparity16) {
    rightColumnKeys(best, bestSum, width, minD, rightKey);
    for (int x = 0; x < width; ++x) {
        const int d = best[x];
        const int rightD = static_cast<int>(rightKey[d < 0 ? width : x - minD - d] & 0xFFFF);
        const bool kept = d < 0 || std::abs(rightD - d) <= maxDiff;
        disparity16[x] = kept ? disparity16[x] : 0;
    }
}

void medianRowScalar(const uint16_t *const *rows, int width, int size, uint16_t *, float invalid, float *out) {
    const int r = size / 2;
    uint16_t window[kMaxMedianPx * kMaxMedianPx];
    for (int x = 0; x < width; ++x) {
        int n = 0;
        for (int i = 0; i < size; ++i)
            for (int j = -r; j <= r; ++j) window[n++] = rows[i][std::clamp(x + j, 0, width - 1)];
        std::nth_element(window, window + n / 2, window + n);
        const uint16_t median = window[n / 2];
        out[x] = median == 0 ? invalid : static_cast<float>(median) * (1.0f / 16);
    }
}

} // namespace

const Kernels &scalarKernels() {
    static const Kernels k{"scalar", kDispAlign, censusRowScalar, costScratchScalar, costRowScalar, costRowScalar,
                           pathRowScalar, horizontalRowScalar, horizontalPathsScalar, addPathRowScalar, wtaRowScalar,
                           upWtaRowScalar, leftRightRowScalar, medianRowScalar};
    return k;
}

} // namespace sgm
