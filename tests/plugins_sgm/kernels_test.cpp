// SPDX-License-Identifier: MIT
// sgm kernels: every SIMD table (baseline, AVX2 where the CPU has it) equals the scalar
// reference bit for bit, kernel by kernel and on whole pairs: random inputs, odd sizes,
// widths that are no whole number of vectors.
#include "sgm_engine.hpp"
#include "sgm_kernels.hpp"
#include "sgm_median.hpp"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <algorithm>
#include <cstring>
#include <iterator>
#include <random>
#include <string>
#include <vector>

namespace {

using sgm::Kernels;

// The SIMD tables this build and CPU have, by name (a stable test name).
std::vector<std::string> simdTables() {
    std::vector<std::string> t;
    if (sgm::baselineKernels()) t.push_back("baseline");
    if (sgm::avx2Kernels()) t.push_back("avx2");
    if (sgm::avx512Kernels()) t.push_back("avx512");
    return t;
}

class SimdKernels : public ::testing::TestWithParam<std::string> {
protected:
    const Kernels &simd() const {
        return GetParam() == "avx512" ? *sgm::avx512Kernels()
               : GetParam() == "avx2" ? *sgm::avx2Kernels()
                                      : *sgm::baselineKernels();
    }
    const Kernels &ref() const { return sgm::scalarKernels(); }
    std::mt19937_64 rng{20};
    uint8_t byte() { return static_cast<uint8_t>(rng()); }
};

const int kWidths[] = {1, 2, 7, 15, 16, 17, 31, 33, 63, 65, 97, 130};

TEST_P(SimdKernels, CensusEqualsTheReference) {
    const std::pair<int, int> windows[] = {{3, 3}, {5, 5}, {9, 7}, {7, 9}, {11, 5}, {5, 3}};
    for (int width : kWidths)
        for (auto [cw, ch] : windows) {
            cv::Mat padded(ch, width + cw - 1, CV_8UC1);
            cv::randu(padded, 0, 256);
            // Flat patches too: equal neighbours must not set a bit.
            padded(cv::Rect(0, 0, std::min(3, padded.cols), ch)).setTo(7);
            std::vector<const uint8_t *> rows(static_cast<size_t>(ch));
            for (int j = 0; j < ch; ++j) rows[static_cast<size_t>(j)] = padded.ptr<uint8_t>(j) + cw / 2;
            for (bool symmetric : {false, true}) {
                std::vector<uint64_t> a(static_cast<size_t>(width), 1), b(static_cast<size_t>(width), 2);
                ref().censusRow(rows.data(), width, cw, ch, symmetric, a.data());
                simd().censusRow(rows.data(), width, cw, ch, symmetric, b.data());
                ASSERT_EQ(a, b) << "width " << width << ", window " << cw << "x" << ch << (symmetric ? ", centre-symmetric" : "");
                if (symmetric)
                    for (uint64_t word : a) ASSERT_EQ(word >> sgm::censusBits(cw, ch, true), 0u);
            }
        }
}

TEST(CentreSymmetricCensus, ComparesEachPixelWithItsMirror) {
    // A 3 x 3 window, pixels 0..8 row-major: bit k compares pixel k with pixel 8 - k.
    const uint8_t r0[] = {1, 9, 5}, r1[] = {4, 0, 3}, r2[] = {2, 6, 8};
    const uint8_t *rows[] = {r0 + 1, r1 + 1, r2 + 1};
    uint64_t word = 0;
    sgm::scalarKernels().censusRow(rows, 1, 3, 3, true, &word);
    // 1 < 8, 9 < 6 no, 5 < 2 no, 4 < 3 no.
    EXPECT_EQ(word, 0b0001u);
}

TEST_P(SimdKernels, CostsEqualTheReference) {
    for (int width : kWidths)
        for (int minD : {0, 3, 17})
            for (int numDisp : {16, 48, 64, 128, 256}) {
                const int dp = sgm::paddedDisparities(numDisp, simd().dispAlign);
                std::vector<uint64_t> left(static_cast<size_t>(width)), right(static_cast<size_t>(width));
                for (auto &v : left) v = rng() & ((uint64_t(1) << 62) - 1);
                for (auto &v : right) v = rng();
                std::vector<uint64_t> scratch(simd().costScratchWords(width, minD, dp) + 1);
                std::vector<uint8_t> a(static_cast<size_t>(width) * dp, 1), b(static_cast<size_t>(width) * dp, 2);
                ref().costRow(left.data(), right.data(), width, minD, numDisp, dp, nullptr, a.data());
                simd().costRow(left.data(), right.data(), width, minD, numDisp, dp, scratch.data(), b.data());
                ASSERT_EQ(a, b) << "width " << width << ", min_disparity " << minD << ", num_disparities " << numDisp;
                // Words below 2^32 (windows of at most 32 bits) through the 32-bit kernel.
                for (auto &v : left) v &= 0xFFFFFFFFu;
                for (auto &v : right) v &= 0xFFFFFFFFu;
                ref().costRow(left.data(), right.data(), width, minD, numDisp, dp, nullptr, a.data());
                simd().costRow32(left.data(), right.data(), width, minD, numDisp, dp, scratch.data(), b.data());
                ASSERT_EQ(a, b) << "32-bit words, width " << width << ", min_disparity " << minD << ", num_disparities "
                                << numDisp;
            }
}

// Random costs (with invalid ones), random predecessors with their sentinels, penalties
// by intensity step; both kernels must write the same path costs, minima and sums.
struct PathCase {
    int width, dp;
    std::vector<uint8_t> cost, prevL, prevMin, grey, greyPrev, lut;
    std::vector<uint16_t> sum;
};

PathCase pathCase(std::mt19937_64 &rng, int width, int numDisp, int p1, int p2, int align) {
    PathCase c;
    c.width = width;
    c.dp = sgm::paddedDisparities(numDisp, align);
    const size_t stride = sgm::pathStride(c.dp);
    c.cost.resize(static_cast<size_t>(width) * c.dp);
    for (auto &v : c.cost) v = rng() % 8 == 0 ? sgm::kCostInvalid : static_cast<uint8_t>(rng() % 63);
    c.prevL.assign(static_cast<size_t>(width) * stride, sgm::kCostInvalid);
    c.prevMin.resize(static_cast<size_t>(width));
    for (int x = 0; x < width; ++x) {
        uint8_t least = 255;
        for (int d = 0; d < c.dp; ++d) {
            const uint8_t v = static_cast<uint8_t>(rng() % 200);
            c.prevL[x * stride + 1 + d] = v;
            least = std::min(least, v);
        }
        c.prevMin[static_cast<size_t>(x)] = least;
    }
    c.grey.resize(static_cast<size_t>(width));
    c.greyPrev.resize(static_cast<size_t>(width));
    for (auto &v : c.grey) v = static_cast<uint8_t>(rng());
    for (auto &v : c.greyPrev) v = static_cast<uint8_t>(rng());
    c.lut.resize(511); // by signed intensity step (PathParams::p2ByStep)
    for (int g = 0; g < 256; ++g)
        c.lut[static_cast<size_t>(255 + g)] = c.lut[static_cast<size_t>(255 - g)] =
            static_cast<uint8_t>(std::max(p1, p2 * 16 / (16 + g)));
    c.sum.resize(static_cast<size_t>(width) * c.dp);
    for (auto &v : c.sum) v = static_cast<uint16_t>(rng() % 1500);
    return c;
}

TEST_P(SimdKernels, PathsEqualTheReference) {
    // Path sets as the engine runs them: one vertical, three from above, and others.
    const std::vector<std::vector<int>> sets = {{0}, {-1, 0, 1}, {1}, {-1}, {1, -1}};
    for (int width : kWidths)
        for (int numDisp : {16, 64, 96, 256})
            for (const std::vector<int> &dxs : sets)
                for (bool first : {false, true})
                    for (bool init : {false, true}) {
                        const int n = static_cast<int>(dxs.size());
                        std::vector<PathCase> cases;
                        const int p1 = 1 + static_cast<int>(rng() % 20), p2 = 60 + static_cast<int>(rng() % 130);
                        for (int i = 0; i < n; ++i) cases.push_back(pathCase(rng, width, numDisp, p1, p2, simd().dispAlign));
                        const PathCase &c = cases[0];
                        const sgm::PathParams pp{p1, c.lut.data() + 255};
                        const size_t rowBytes = static_cast<size_t>(width) * sgm::pathStride(c.dp);
                        std::vector<std::vector<uint8_t>> la(3, std::vector<uint8_t>(rowBytes, sgm::kCostInvalid)), lb = la;
                        std::vector<std::vector<uint8_t>> ma(3, std::vector<uint8_t>(static_cast<size_t>(width))), mb = ma;
                        sgm::RowPaths ra{}, rb{};
                        ra.count = rb.count = n;
                        for (int i = 0; i < n; ++i) {
                            ra.dx[i] = rb.dx[i] = dxs[static_cast<size_t>(i)];
                            ra.prevL[i] = rb.prevL[i] = first ? nullptr : cases[static_cast<size_t>(i)].prevL.data();
                            ra.prevMin[i] = rb.prevMin[i] = cases[static_cast<size_t>(i)].prevMin.data();
                            ra.curL[i] = la[static_cast<size_t>(i)].data();
                            rb.curL[i] = lb[static_cast<size_t>(i)].data();
                            ra.curMin[i] = ma[static_cast<size_t>(i)].data();
                            rb.curMin[i] = mb[static_cast<size_t>(i)].data();
                        }
                        std::vector<uint16_t> sa = c.sum, sb = c.sum;
                        ref().pathRow(c.cost.data(), width, c.dp, ra, c.grey.data(), c.greyPrev.data(), pp, sa.data(), init);
                        simd().pathRow(c.cost.data(), width, c.dp, rb, c.grey.data(), c.greyPrev.data(), pp, sb.data(), init);
                        const std::string what = "width " + std::to_string(width) + ", num_disparities " +
                                                 std::to_string(numDisp) + ", paths " + std::to_string(n);
                        ASSERT_EQ(la, lb) << what;
                        ASSERT_EQ(ma, mb) << what;
                        ASSERT_EQ(sa, sb) << what;

                        // No sums: the same path costs and minima as with them, in both tables.
                        for (int scalar : {1, 0}) {
                            std::vector<std::vector<uint8_t>> lc(3, std::vector<uint8_t>(rowBytes, sgm::kCostInvalid));
                            std::vector<std::vector<uint8_t>> mc(3, std::vector<uint8_t>(static_cast<size_t>(width)));
                            sgm::RowPaths rc = ra;
                            for (int i = 0; i < n; ++i) {
                                rc.curL[i] = lc[static_cast<size_t>(i)].data();
                                rc.curMin[i] = mc[static_cast<size_t>(i)].data();
                            }
                            (scalar ? ref() : simd()).pathRow(c.cost.data(), width, c.dp, rc, c.grey.data(),
                                                              c.greyPrev.data(), pp, nullptr, init);
                            ASSERT_EQ(lc, la) << "no sums, scalar " << scalar << ", " << what;
                            ASSERT_EQ(mc, ma) << "no sums, scalar " << scalar << ", " << what;
                        }

                        // A stored path row added to sums.
                        sa = c.sum;
                        sb = c.sum;
                        ref().addPathRow(cases[0].prevL.data(), width, c.dp, sa.data());
                        simd().addPathRow(cases[0].prevL.data(), width, c.dp, sb.data());
                        ASSERT_EQ(sa, sb) << "add path row, " << what;

                        std::vector<uint8_t> scratch(sgm::horizontalScratch(width, c.dp), sgm::kCostInvalid);
                        sa = c.sum;
                        sb = c.sum;
                        ref().horizontalRow(c.cost.data(), width, c.dp, c.grey.data(), pp, scratch.data(), sa.data(), init);
                        simd().horizontalRow(c.cost.data(), width, c.dp, c.grey.data(), pp, scratch.data(), sb.data(), init);
                        ASSERT_EQ(sa, sb) << "horizontal, " << what;
                    }
}

// The horizontal paths of two rows at once equal those of each row alone (stored sums).
// Both horizontal paths of one row and of two rows side by side, stored whole: the
// reference's and the table's equal, and together they are horizontalRow's sums.
TEST_P(SimdKernels, HorizontalPathsEqualTheReference) {
    for (int width : kWidths)
        for (int numDisp : {16, 64, 96, 128, 256})
            for (int rows : {1, 2}) {
                const int p1 = 1 + static_cast<int>(rng() % 20), p2 = 60 + static_cast<int>(rng() % 130);
                const int align = simd().dispAlign;
                const PathCase a = pathCase(rng, width, numDisp, p1, p2, align), b = pathCase(rng, width, numDisp, p1, p2, align);
                const sgm::PathParams pp{p1, a.lut.data() + 255};
                std::vector<uint8_t> scratch(sgm::horizontalScratch(width, a.dp), sgm::kCostInvalid);
                const uint8_t *costs[2] = {a.cost.data(), b.cost.data()}, *greys[2] = {a.grey.data(), b.grey.data()};
                const auto run = [&](const Kernels &table) {
                    std::vector<std::vector<uint8_t>> out(4, std::vector<uint8_t>(static_cast<size_t>(width) * a.dp, 7));
                    uint8_t *const forward[2] = {out[0].data(), out[2].data()}, *const backward[2] = {out[1].data(), out[3].data()};
                    table.horizontalPaths(costs, rows, width, a.dp, greys, pp, scratch.data(), forward, backward);
                    return out;
                };
                const auto ra = run(ref()), rb = run(simd());
                const std::string what = "width " + std::to_string(width) + ", num_disparities " +
                                         std::to_string(numDisp) + ", rows " + std::to_string(rows);
                ASSERT_EQ(ra, rb) << what;
                std::vector<uint16_t> sum(static_cast<size_t>(width) * a.dp);
                ref().horizontalRow(a.cost.data(), width, a.dp, a.grey.data(), pp, scratch.data(), sum.data(), true);
                for (size_t i = 0; i < sum.size(); ++i)
                    ASSERT_EQ(sum[i], ra[0][i] + ra[1][i]) << "the two paths against horizontalRow's sums, " << what;
            }
}

// The fused pass up of 4 paths (vertical path, sums, winner) equals the kernels it fuses.
// What the fused pass up of one table writes for a row.
struct UpWtaResult {
    std::vector<uint8_t> path, mins;
    std::vector<int16_t> best;
    std::vector<uint16_t> bestSum, disparity16;
};
UpWtaResult upWta(const Kernels &table, const uint8_t *cost, int width, int dp, const uint8_t *prevL,
                  const uint8_t *prevMin, const uint8_t *grey, const uint8_t *greyPrev, const sgm::PathParams &pp,
                  const uint8_t *kept, const uint8_t *forward, const uint8_t *backward, const sgm::WtaParams &wp) {
    const size_t w = static_cast<size_t>(width);
    UpWtaResult r{std::vector<uint8_t>(w * sgm::pathStride(dp), sgm::kCostInvalid), std::vector<uint8_t>(w),
                  std::vector<int16_t>(w), std::vector<uint16_t>(w), std::vector<uint16_t>(w)};
    sgm::RowPaths rp{};
    rp.count = 1;
    rp.prevL[0] = prevL; // NULL: the path starts at this row
    rp.prevMin[0] = prevMin;
    rp.curL[0] = r.path.data();
    rp.curMin[0] = r.mins.data();
    table.upWtaRow(cost, width, dp, rp, grey, greyPrev, pp, kept, forward, backward, wp, r.best.data(),
                   r.bestSum.data(), r.disparity16.data());
    return r;
}
void expectSameUpWta(const UpWtaResult &a, const UpWtaResult &b, const std::string &what) {
    ASSERT_EQ(a.path, b.path) << what;
    ASSERT_EQ(a.mins, b.mins) << what;
    ASSERT_EQ(a.best, b.best) << what;
    ASSERT_EQ(a.bestSum, b.bestSum) << what;
    ASSERT_EQ(a.disparity16, b.disparity16) << what;
}

TEST_P(SimdKernels, FusedPassUpEqualsTheReference) {
    for (int width : kWidths)
        for (int numDisp : {16, 48, 64, 96, 128, 256})
            for (bool first : {false, true})
                for (int uniqueness : {0, 10, 60})
                    for (bool subpixel : {false, true}) {
                        const int p1 = 1 + static_cast<int>(rng() % 20), p2 = 60 + static_cast<int>(rng() % 130);
                        const PathCase c = pathCase(rng, width, numDisp, p1, p2, simd().dispAlign);
                        const PathCase kept = pathCase(rng, width, numDisp, p1, p2, simd().dispAlign);
                        const sgm::PathParams pp{p1, c.lut.data() + 255};
                        const int minD = uniqueness == 10 ? 5 : 0;
                        const sgm::WtaParams wp{minD, numDisp, c.dp, uniqueness, subpixel};
                        // The horizontal paths, 8-bit, in the cost-row layout.
                        std::vector<uint8_t> forward(c.cost.size()), backward(c.cost.size());
                        for (auto &v : forward) v = byte();
                        for (auto &v : backward) v = byte();
                        const std::vector<uint8_t> given = forward;
                        const uint8_t *prevL = first ? nullptr : c.prevL.data();
                        const auto run = [&](const Kernels &table) {
                            return upWta(table, c.cost.data(), width, c.dp, prevL, c.prevMin.data(), c.grey.data(),
                                         c.greyPrev.data(), pp, kept.prevL.data(), forward.data(), backward.data(), wp);
                        };
                        const std::string what = "width " + std::to_string(width) + ", num_disparities " +
                                                 std::to_string(numDisp) + ", uniqueness " + std::to_string(uniqueness);
                        ASSERT_NO_FATAL_FAILURE(expectSameUpWta(run(ref()), run(simd()), what));
                        ASSERT_EQ(forward, given) << "the horizontal paths are read only, " << what;
                    }
}

// The fused pass up's uniqueness test at its boundary, as WinnerTakesAllUniquenessBoundary
// below for wtaRow: per pixel a least sum m at b and a rival at b + k (k = -3 .. 3) whose
// sum is the largest that fails the test or the least that passes. The path from below
// starts at this row (its costs are the row's costs), so each sum is laid out over the
// two horizontal paths, the costs and the kept path (<= 255 each).
TEST_P(SimdKernels, FusedPassUpUniquenessBoundary) {
    for (int numDisp : {16, 64, 128, 256})
        for (int uniqueness : {1, 8, 15, 50}) {
            const int width = numDisp + 61, dp = sgm::paddedDisparities(numDisp, simd().dispAlign);
            const size_t w = static_cast<size_t>(width), stride = sgm::pathStride(dp);
            std::vector<uint8_t> cost(w * dp), kept(w * stride, sgm::kCostInvalid), grey(w, 100);
            std::vector<uint8_t> forward(w * dp), backward(w * dp);
            for (int x = 0; x < width; ++x) {
                std::vector<int> target(static_cast<size_t>(dp));
                for (auto &t : target) t = 700 + static_cast<int>(rng() % (sgm::kMaxSum4 - 699));
                const int b = static_cast<int>(rng() % static_cast<unsigned>(numDisp));
                const int m = 50 + static_cast<int>(rng() % 250);
                const int rival = std::clamp(b + static_cast<int>(rng() % 7) - 3, 0, numDisp - 1);
                const int passing = (m * 100 + (100 - uniqueness) - 1) / (100 - uniqueness);
                target[static_cast<size_t>(b)] = m;
                if (rival != b) target[static_cast<size_t>(rival)] = std::max(m, passing - static_cast<int>(rng() % 2));
                for (int d = 0; d < dp; ++d) { // the target in quarters
                    const int t = target[static_cast<size_t>(d)], q = (t + 3) / 4; // the last: t - 3q <= q
                    forward[x * dp + d] = static_cast<uint8_t>(q);
                    backward[x * dp + d] = static_cast<uint8_t>(q);
                    cost[x * dp + d] = static_cast<uint8_t>(q);
                    kept[x * stride + 1 + d] = static_cast<uint8_t>(t - 3 * q);
                }
            }
            const uint8_t lut[511] = {};
            const sgm::PathParams pp{10, lut + 255};
            const sgm::WtaParams wp{0, numDisp, dp, uniqueness, true};
            const std::vector<uint8_t> noMin(w, 255);
            const auto run = [&](const Kernels &table) {
                return upWta(table, cost.data(), width, dp, nullptr, noMin.data(), grey.data(), grey.data(), pp,
                             kept.data(), forward.data(), backward.data(), wp);
            };
            const std::string what = "num_disparities " + std::to_string(numDisp) + ", uniqueness " +
                                     std::to_string(uniqueness);
            const UpWtaResult a = run(ref());
            ASSERT_NO_FATAL_FAILURE(expectSameUpWta(a, run(simd()), what));
            const std::vector<uint16_t> &da = a.disparity16;
            const auto rejected = std::count(da.begin() + numDisp, da.end(), 0);
            EXPECT_GT(rejected, 0) << what;
            EXPECT_LT(rejected, width - numDisp) << what;
        }
}

// The winner of every pixel of a row of sums, the reference's and this table's: equal.
// disparity16: the reference's disparities, when wanted.
void wtaEqualsTheReference(const sgm::Kernels &table, const std::vector<uint16_t> &sum, int width,
                           const sgm::WtaParams &wp, const std::string &what,
                           std::vector<uint16_t> *disparity16 = nullptr) {
    const size_t n = static_cast<size_t>(width);
    std::vector<int16_t> ba(n), bb(n);
    std::vector<uint16_t> sa(n), sb(n), da(n), db(n);
    sgm::scalarKernels().wtaRow(sum.data(), width, wp, ba.data(), sa.data(), da.data());
    table.wtaRow(sum.data(), width, wp, bb.data(), sb.data(), db.data());
    ASSERT_EQ(ba, bb) << what;
    ASSERT_EQ(sa, sb) << what;
    ASSERT_EQ(da, db) << what;
    if (disparity16) *disparity16 = da;
}

TEST_P(SimdKernels, WinnerTakesAllEqualsTheReference) {
    for (int width : kWidths)
        for (int numDisp : {16, 48, 64, 256})
            for (int minD : {0, 5})
                for (int uniqueness : {0, 5, 15, 60})
                    for (bool subpixel : {false, true})
                        for (int range : {4, 2000}) { // small ranges: many ties
                            const int dp = sgm::paddedDisparities(numDisp, simd().dispAlign);
                            std::vector<uint16_t> sum(static_cast<size_t>(width) * dp);
                            for (auto &v : sum) v = static_cast<uint16_t>(rng() % range);
                            const sgm::WtaParams wp{minD, numDisp, dp, uniqueness, subpixel};
                            const std::string what = "width " + std::to_string(width) + ", num_disparities " +
                                                     std::to_string(numDisp) + ", uniqueness " + std::to_string(uniqueness);
                            ASSERT_NO_FATAL_FAILURE(wtaEqualsTheReference(simd(), sum, width, wp, what));
                        }
}

// The uniqueness test at its boundary: per pixel a least sum m at b and a rival at b + k
// (k = -3 .. 3, so also the excluded neighbours b - 1 and b + 1) whose sum is the
// largest that fails the test, or the least that passes (s * (100 - u) against m * 100).
TEST_P(SimdKernels, WinnerTakesAllUniquenessBoundary) {
    for (int numDisp : {16, 64, 128})
        for (int uniqueness : {1, 8, 15, 50}) {
            const int width = numDisp + 61, dp = sgm::paddedDisparities(numDisp, simd().dispAlign);
            std::vector<uint16_t> sum(static_cast<size_t>(width) * dp);
            for (int x = 0; x < width; ++x) {
                uint16_t *s = sum.data() + static_cast<size_t>(x) * dp;
                for (int d = 0; d < dp; ++d) s[d] = static_cast<uint16_t>(2000 + rng() % 100);
                const int b = static_cast<int>(rng() % static_cast<unsigned>(numDisp));
                const int m = 100 + static_cast<int>(rng() % 400);
                const int rival = std::clamp(b + static_cast<int>(rng() % 7) - 3, 0, numDisp - 1);
                // The least s with s * (100 - u) >= m * 100, minus 0 or 1.
                const int passing = (m * 100 + (100 - uniqueness) - 1) / (100 - uniqueness);
                s[b] = static_cast<uint16_t>(m);
                if (rival != b) s[rival] = static_cast<uint16_t>(std::max(m, passing - static_cast<int>(rng() % 2)));
            }
            const sgm::WtaParams wp{0, numDisp, dp, uniqueness, true};
            const std::string what = "num_disparities " + std::to_string(numDisp) + ", uniqueness " +
                                     std::to_string(uniqueness);
            std::vector<uint16_t> da;
            ASSERT_NO_FATAL_FAILURE(wtaEqualsTheReference(simd(), sum, width, wp, what, &da));
            // Both outcomes occur, or the boundary was not reached.
            const auto rejected = std::count(da.begin() + numDisp, da.end(), 0);
            EXPECT_GT(rejected, 0) << what;
            EXPECT_LT(rejected, width - numDisp) << what;
        }
}

// A textured pair with a step in depth, at an odd size.
std::pair<cv::Mat, cv::Mat> texturedPair(cv::Size size, uint64_t seed) {
    cv::Mat texture(size.height, size.width + 40, CV_8UC1);
    cv::RNG r(seed);
    r.fill(texture, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
    cv::Mat left = texture.colRange(0, size.width).clone();
    cv::Mat right = texture.colRange(12, 12 + size.width).clone();
    // A nearer square: 25 px.
    const cv::Rect box(size.width / 3, size.height / 4, size.width / 3, size.height / 2);
    texture(cv::Rect(box.x + 25, box.y, box.width, box.height)).copyTo(left(box));
    return {left, right};
}

TEST_P(SimdKernels, WholePairsEqualTheReference) {
    const auto [left, right] = texturedPair({123, 77}, 3);
    for (int paths : {4, 5, 8})
        for (int stripes : {1, 3})
            for (bool symmetric : {false, true}) {
                sgm::Settings s;
                s.numDisparities = 48;
                s.minDisparity = 2;
                s.paths = paths;
                s.stripes = stripes;
                s.p2IntensityStep = paths == 8 ? 24 : 0;
                s.censusSymmetric = symmetric;
                sgm::Engine a(s, sgm::scalarKernels()), b(s, simd());
                const cv::Mat fa = a.computeFixed(left, right).clone();
                const cv::Mat fb = b.computeFixed(left, right);
                EXPECT_EQ(cv::countNonZero(fa != fb), 0)
                    << "paths " << paths << ", stripes " << stripes << (symmetric ? ", centre-symmetric" : "");
                EXPECT_GT(cv::countNonZero(fa), left.total() / 2) << "paths " << paths;
            }
}

// The left-right check of every width: the same disparities as the reference. Winners
// near their neighbours' (runs of d, d + 1: many pixels share a right column), some with
// equal sums, the left margin without candidate.
TEST_P(SimdKernels, LeftRightCheckEqualsTheReference) {
    for (int width : {1, 2, 7, 15, 16, 17, 31, 33, 63, 65, 97, 130, 641})
        for (int minD : {0, 5})
            for (int maxDiff : {0, 1, 3}) {
                const size_t w = static_cast<size_t>(width);
                std::vector<int16_t> best(w);
                std::vector<uint16_t> bestSum(w), d16(w);
                int d = 0;
                for (int x = 0; x < width; ++x) {
                    d = std::clamp(d + static_cast<int>(rng() % 5) - 2, 0, 40);
                    best[x] = x - minD - d < 0 ? -1 : static_cast<int16_t>(d);
                    bestSum[x] = static_cast<uint16_t>(rng() % 8);
                    d16[x] = best[x] < 0 ? 0 : static_cast<uint16_t>(1 + rng() % 4000);
                }
                std::vector<uint32_t> keys(w + 1);
                std::vector<uint16_t> a = d16, b = d16;
                ref().leftRightRow(best.data(), bestSum.data(), width, minD, maxDiff, keys.data(), a.data());
                simd().leftRightRow(best.data(), bestSum.data(), width, minD, maxDiff, keys.data(), b.data());
                const std::string what = "width " + std::to_string(width) + ", min_disparity " + std::to_string(minD) +
                                         ", disp12_max_diff " + std::to_string(maxDiff);
                ASSERT_EQ(a, b) << what;
                if (width > 100) { // both outcomes occur
                    EXPECT_GT(std::count(a.begin(), a.end(), 0), std::count(d16.begin(), d16.end(), 0)) << what;
                    EXPECT_GT(std::count_if(a.begin(), a.end(), [](uint16_t v) { return v > 0; }), 0) << what;
                }
            }
}

// The median filter of every width and size: the same floats as the reference (random
// disparities, a third of them 0, so that invalid medians occur).
TEST_P(SimdKernels, MedianEqualsTheReference) {
    for (int width : {1, 2, 7, 15, 16, 17, 31, 33, 63, 65, 97, 130, 641})
        for (int size : {1, 3, 5}) {
            std::vector<std::vector<uint16_t>> rows(static_cast<size_t>(size), std::vector<uint16_t>(width));
            const uint16_t *at[sgm::kMaxMedianPx];
            for (int r = 0; r < size; ++r) {
                for (auto &v : rows[static_cast<size_t>(r)]) v = rng() % 3 == 0 ? 0 : static_cast<uint16_t>(rng());
                at[r] = rows[static_cast<size_t>(r)].data();
            }
            std::vector<uint16_t> scratch(sgm::medianScratch(width));
            std::vector<float> a(static_cast<size_t>(width)), b(a.size());
            ref().medianRow(at, width, size, scratch.data(), -1.0f, a.data());
            simd().medianRow(at, width, size, scratch.data(), -1.0f, b.data());
            ASSERT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(float)))
                << "width " << width << ", median_px " << size;
        }
}

INSTANTIATE_TEST_SUITE_P(Tables, SimdKernels, ::testing::ValuesIn(simdTables()),
                         [](const ::testing::TestParamInfo<std::string> &i) { return i.param; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(SimdKernels);

// The median networks of sgm_median.hpp (the columns sorted, then the network) leave the
// median on the middle wire for every input of 0s and 1s, so for every input (the 0-1
// principle): all 2^9 and 2^25 of them, 64 at a time (bit i of a word: input i).
bool selectsTheMedian(int k, const sgm::MedianComparator *net, size_t comparators) {
    const int n = k * k;
    const uint64_t inputs = uint64_t{1} << n, words = std::max<uint64_t>(1, inputs / 64);
    // Bits 0..5 of the input index vary inside a word: wire w < 6 has a fixed pattern.
    const uint64_t lowWire[6] = {0xAAAAAAAAAAAAAAAAull, 0xCCCCCCCCCCCCCCCCull, 0xF0F0F0F0F0F0F0F0ull,
                                 0xFF00FF00FF00FF00ull, 0xFFFF0000FFFF0000ull, 0xFFFFFFFF00000000ull};
    // Lanes of a word (its 6 low bits) with at least c ones.
    uint64_t lanesWith[8] = {};
    for (int lane = 0; lane < 64; ++lane)
        for (int c = 0; c <= __builtin_popcount(lane); ++c) lanesWith[c] |= uint64_t{1} << lane;
    const uint64_t used = inputs >= 64 ? ~uint64_t{0} : (uint64_t{1} << inputs) - 1;
    for (uint64_t word = 0; word < words; ++word) {
        uint64_t v[25];
        for (int w = 0; w < n; ++w) v[w] = w < 6 ? lowWire[w] : ((word >> (w - 6)) & 1 ? ~uint64_t{0} : 0);
        const auto exchange = [&](int i, int j) {
            const uint64_t a = v[i], b = v[j];
            v[i] = a & b;
            v[j] = a | b;
        };
        for (int c = 0; c < k; ++c) { // each column sorted, top to bottom
            if (k == 3)
                for (const auto &p : sgm::kSort3) exchange(p[0] * k + c, p[1] * k + c);
            else
                for (const auto &p : sgm::kSort5) exchange(p[0] * k + c, p[1] * k + c);
        }
        for (size_t c = 0; c < comparators; ++c) exchange(net[c].i, net[c].j);
        // The median is 1 exactly when at least n / 2 + 1 inputs are 1: the word's index
        // gives the inputs 6 and up, the lane the inputs 0 to 5.
        const int need = n / 2 + 1 - __builtin_popcountll(word);
        const uint64_t expected = need <= 0 ? ~uint64_t{0} : need > 6 ? 0 : lanesWith[need];
        if (((v[n / 2] ^ expected) & used) != 0) return false;
    }
    return true;
}

TEST(MedianNetworks, SelectTheMedianOfEveryZeroOneInput) {
    EXPECT_TRUE(selectsTheMedian(3, sgm::kMedianOf9, std::size(sgm::kMedianOf9)));
    EXPECT_TRUE(selectsTheMedian(5, sgm::kMedianOf25, std::size(sgm::kMedianOf25)));
    // Without its last comparator neither does: the check can fail.
    EXPECT_FALSE(selectsTheMedian(3, sgm::kMedianOf9, std::size(sgm::kMedianOf9) - 1));
    EXPECT_FALSE(selectsTheMedian(5, sgm::kMedianOf25, std::size(sgm::kMedianOf25) - 1));
}

// Buffers are made for the first pair of a size and reused for every later one.
TEST(SgmEngine, AllocatesOncePerImageSize) {
    const auto [left, right] = texturedPair({160, 96}, 4);
    sgm::Engine e(sgm::Settings{}, sgm::bestKernels());
    cv::Mat d(left.size(), CV_32FC1);
    for (int i = 0; i < 3; ++i) e.compute(left, right, d, -1.0f);
    EXPECT_EQ(e.allocations(), 1);
    const auto [l2, r2] = texturedPair({161, 97}, 4);
    cv::Mat d2(l2.size(), CV_32FC1);
    e.compute(l2, r2, d2, -1.0f);
    EXPECT_EQ(e.allocations(), 2);
}

// The median and the conversion run in the stripes, in parallel (the rows around a border
// between stripes once both are done): the result is OpenCV's medianBlur over the whole
// fixed-point map, for every median size, the reference and the fastest table, and
// heights and stripe counts that leave stripes of unequal size (and stripes of fewer rows
// than a window).
TEST(SgmEngine, MedianInStripesEqualsTheWholeImage) {
    for (const cv::Size size : {cv::Size(123, 77), cv::Size(90, 300), cv::Size(64, 20)})
        for (int median : {1, 3, 5})
            for (int stripes : {1, 2, 7}) {
                const auto [left, right] = texturedPair(size, 5);
                sgm::Settings s;
                s.numDisparities = 32;
                s.medianPx = median;
                s.stripes = stripes;
                for (const sgm::Kernels *table : {&sgm::scalarKernels(), &sgm::bestKernels()}) {
                    sgm::Engine e(s, *table);
                    cv::Mat d(left.size(), CV_32FC1);
                    e.compute(left, right, d, -1.0f);
                    const cv::Mat fixed = e.computeFixed(left, right).clone();
                    cv::Mat filtered = fixed;
                    if (median > 1) cv::medianBlur(fixed, filtered, median);
                    cv::Mat expected(left.size(), CV_32FC1);
                    for (int y = 0; y < expected.rows; ++y)
                        for (int x = 0; x < expected.cols; ++x) {
                            const int v = filtered.at<uint16_t>(y, x);
                            expected.at<float>(y, x) = v == 0 ? -1.0f : v / 16.0f;
                        }
                    EXPECT_EQ(cv::countNonZero(expected != d), 0)
                        << size << ", median " << median << ", stripes " << stripes << ", " << table->name;
                    EXPECT_GT(cv::countNonZero(expected > 0), static_cast<int>(left.total() / 3)) << size;
                }
            }
}

// The volume of 4 and 8 paths is bounded: refused, with the figures, before any buffer.
TEST(SgmEngine, RefusesAPairOverTheMemoryBound) {
    sgm::Settings s;
    s.numDisparities = 256;
    s.maxMemoryBytes = 64.0 * 1048576;
    sgm::Engine e(s, sgm::bestKernels());
    const cv::Mat big(1000, 1200, CV_8UC1, cv::Scalar(0));
    try {
        e.computeFixed(big, big);
        FAIL() << "no refusal";
    } catch (const std::invalid_argument &ex) {
        const std::string m = ex.what();
        EXPECT_NE(m.find("1200x1000"), std::string::npos) << m;
        EXPECT_NE(m.find("max_memory_mb = 64"), std::string::npos) << m;
        EXPECT_NE(m.find("paths 5"), std::string::npos) << m;
    }
    EXPECT_EQ(e.allocations(), 0);
    s.paths = 5; // no volume: fits
    sgm::Engine five(s, sgm::bestKernels());
    EXPECT_NO_THROW(five.computeFixed(big, big));
}

} // namespace
