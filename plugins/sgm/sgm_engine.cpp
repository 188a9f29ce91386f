// SPDX-License-Identifier: MIT
// sgm: the matching of one pair, per stripe of rows in parallel: the census of both
// images, the costs, the path aggregation (one pass down, and for 4 and 8 paths one pass
// up over volumes the pass down kept), winner takes all with the left-right check, then a
// median.
#include "sgm_engine.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace sgm {
namespace {

// The dense option's occlusion test: a run of invalid pixels is an occlusion when the
// disparity on its right exceeds the one on its left by more than this (sgm_fill.hpp).
constexpr float kOcclusionJumpPx = 1.0f;

// The column offsets of the paths whose predecessors lie in the previous row: the
// vertical one (4 paths), or with the two diagonals (5 and 8 paths).
constexpr int kVertical[] = {0};
constexpr int kVerticalAndDiagonals[] = {-1, 0, 1};

std::string mebibytes(double bytes) { return std::to_string(static_cast<long long>(std::ceil(bytes / 1048576.0))); }

} // namespace

Engine::Engine(const Settings &settings, const Kernels &kernels) : settings_(settings), kernels_(kernels) {
    paddedDisp_ = paddedDisparities(settings_.numDisparities, kernels_.dispAlign);
    // 5 paths: left, right and the three from above, all in one pass down (no volume).
    // 4 and 8: the pass down keeps its sums in a volume, the pass up adds the paths from below.
    twoPass_ = settings_.paths != 5;
    // 4: the pass down keeps only its costs and its 8-bit vertical path (2 bytes per
    // disparity instead of 3, and nothing written back by the pass up); the pass up runs
    // the horizontal paths and sums all four in a row that stays in cache.
    keepDownPath_ = settings_.paths == 4;
    // P2 by intensity step g: smaller across an edge, where disparity jumps are likely
    // (Hirschmueller 2008), never below P1.
    for (int g = 0; g < 256; ++g) {
        int p2 = settings_.p2;
        if (settings_.p2IntensityStep > 0)
            p2 = settings_.p2 * settings_.p2IntensityStep / (settings_.p2IntensityStep + g);
        p2ByStep_[255 + g] = p2ByStep_[255 - g] = static_cast<uint8_t>(std::clamp(p2, settings_.p1, 255));
    }
}

double Engine::workingBytes(int width, int height) const {
    const double w = width, h = height, dp = paddedDisp_, ds = pathStride(paddedDisp_);
    const double rx = settings_.censusWidth / 2, ry = settings_.censusHeight / 2;
    // 8-bit costs, and the 16-bit sums (8 paths) or the 8-bit vertical path (4 paths).
    const double volume = !twoPass_ ? 0 : keepDownPath_ ? w * h * (dp + ds) : w * h * dp * 3;
    // Per stripe its rows and those its paths warm up on: padded grey rows and census words
    // of both images (at most the image's height more than the image, in all).
    const double stripes = std::max(1, settings_.stripes);
    const double rows = h + std::min(h, stripes * 2 * (kStripeOverlapRows + ry));
    const double images = 2 * (w + 2 * rx) * rows + 2 * w * rows * 8 /* census */ + 2 * w * h * 2 /* fixed */;
    const double stripe = w * dp /* cost */ + 6 * w * ds + 6 * w + horizontalScratch(width, paddedDisp_) +
                          w * dp * 4 /* horizontal paths (4 paths) or a row of sums */ + 8 * w +
                          8.0 * kernels_.costScratchWords(width, settings_.minDisparity, paddedDisp_) +
                          2.0 * medianScratch(width);
    // The dense option, at worst every pixel invalid: its column and 8 values, the mark.
    const double fill = settings_.fillDense ? w * h * (4 + 8 * 4 + 1) : 0;
    return volume + images + stripes * stripe + fill;
}

void Engine::prepare(int width, int height) {
    if (width == width_ && height == height_) return;
    const double need = workingBytes(width, height);
    if (need > settings_.maxMemoryBytes)
        throw std::invalid_argument(
            "sgm: paths " + std::to_string(settings_.paths) + " on a " + std::to_string(width) + "x" +
            std::to_string(height) + " pair with num_disparities " + std::to_string(settings_.numDisparities) +
            " needs about " + mebibytes(need) + " MiB of working memory" +
            (keepDownPath_ ? " (volumes of width x height x num_disparities costs and path costs: 2 bytes each)"
             : twoPass_    ? " (volumes of width x height x num_disparities costs and sums: 3 bytes each)"
                           : "") +
            "; expected at most max_memory_mb = " + mebibytes(settings_.maxMemoryBytes) + ": use " +
            (twoPass_ ? "paths 5 (no volume), " : "") + "fewer disparities, smaller images or raise max_memory_mb");
    width_ = width;
    height_ = height;
    const size_t w = static_cast<size_t>(width), h = static_cast<size_t>(height), dp = paddedDisp_;
    const size_t ds = pathStride(paddedDisp_);
    volume_.assign(twoPass_ && !keepDownPath_ ? w * h * dp : 0, 0);
    // The sentinels at d = -1 and d = Dp of every pixel are written here, once.
    downPath_.assign(keepDownPath_ ? w * h * ds : 0, kCostInvalid);
    costVolume_.assign(twoPass_ ? w * h * dp : 0, 0);
    stripes_.assign(static_cast<size_t>(std::clamp(settings_.stripes, 1, height)), Stripe{});
    const int n = static_cast<int>(stripes_.size());
    for (int i = 0; i < n; ++i) {
        Stripe &s = stripes_[static_cast<size_t>(i)];
        s.y0 = height * i / n;
        s.y1 = height * (i + 1) / n;
        s.first = std::max(0, s.y0 - kStripeOverlapRows);
        s.last = std::min(height, s.y1 + kStripeOverlapRows);
        const size_t rows = static_cast<size_t>(s.last - s.first);
        s.censusLeft.assign(rows * w, 0);
        s.censusRight.assign(rows * w, 0);
        s.medianScratch.assign(medianScratch(width), 0);
        s.cost.assign(w * dp, kCostInvalid);
        // The sentinels at d = -1 and d = Dp are written here once and never again.
        s.pathRows.assign(6 * w * ds, kCostInvalid);
        s.pathMins.assign(6 * w, 0);
        s.horizontal.assign(horizontalScratch(width, paddedDisp_), kCostInvalid);
        s.scratchSum.assign(keepDownPath_ ? 0 : w * dp, 0);
        // 4 paths: both horizontal paths of two rows (they run two rows at once).
        s.horizontalPaths.assign(keepDownPath_ ? 4 * w * dp : 0, 0);
        s.costScratch.assign(kernels_.costScratchWords(width, settings_.minDisparity, paddedDisp_), 0);
        s.best.assign(w, -1);
        s.bestSum.assign(w, 0);
        s.rightKey.assign(w + 1, UINT32_MAX); // and a spare column
    }
    fixed_.create(height, width, CV_16UC1);
    ++allocations_;
}

// The census of the rows a stripe matches, of both images. The grey rows they read are
// first padded by replication (left and right: the window never leaves them; above and
// below: the image's first and last rows stand in for those beyond it).
void Engine::censusOf(Stripe &s) {
    const int rx = settings_.censusWidth / 2, ry = settings_.censusHeight / 2;
    const int from = std::max(0, s.first - ry), to = std::min(height_, s.last + ry);
    cv::copyMakeBorder(greyLeft_.rowRange(from, to), s.paddedLeft, 0, 0, rx, rx,
                       cv::BORDER_REPLICATE | cv::BORDER_ISOLATED);
    cv::copyMakeBorder(greyRight_.rowRange(from, to), s.paddedRight, 0, 0, rx, rx,
                       cv::BORDER_REPLICATE | cv::BORDER_ISOLATED);
    const uint8_t *rows[16];
    for (int image = 0; image < 2; ++image) {
        const cv::Mat &padded = image == 0 ? s.paddedLeft : s.paddedRight;
        uint64_t *out = (image == 0 ? s.censusLeft : s.censusRight).data();
        for (int y = s.first; y < s.last; ++y) {
            for (int j = 0; j < settings_.censusHeight; ++j)
                rows[j] = padded.ptr<uint8_t>(std::clamp(y + j - ry, 0, height_ - 1) - from) + rx;
            kernels_.censusRow(rows, width_, settings_.censusWidth, settings_.censusHeight, settings_.censusSymmetric,
                               out + static_cast<size_t>(y - s.first) * width_);
        }
    }
}

const uint8_t *Engine::costRow(Stripe &s, int y, bool own, bool down) {
    const size_t at = static_cast<size_t>(y) * width_;
    uint8_t *volumeRow = twoPass_ && own ? costVolume_.data() + at * paddedDisp_ : nullptr;
    if (volumeRow && !down) return volumeRow; // computed by this stripe's pass down
    uint8_t *out = volumeRow ? volumeRow : s.cost.data();
    // Words of at most 32 bits (the default centre-symmetric 9 x 7: 31) on 32-bit lanes.
    const bool narrow = censusBits(settings_.censusWidth, settings_.censusHeight, settings_.censusSymmetric) <= 32;
    const CostRowFn kernel = narrow ? kernels_.costRow32 : kernels_.costRow;
    const size_t census = static_cast<size_t>(y - s.first) * width_;
    kernel(s.censusLeft.data() + census, s.censusRight.data() + census, width_, settings_.minDisparity,
           settings_.numDisparities, paddedDisp_, s.costScratch.data(), out);
    return out;
}

// Winner takes all on one row of sums, then the left-right check: the right image's
// match of column xr is the left pixel of least sum that chose it (as OpenCV's SGBM
// derives it, from the same sums); a left pixel whose disparity differs from its right
// match's by more than disp12_max_diff is invalid (occluded or mismatched).
void Engine::finishRow(Stripe &s, const uint16_t *sum, int y) {
    if (sum) kernels_.wtaRow(sum, width_, wtaParams(), s.best.data(), s.bestSum.data(), fixed_.ptr<uint16_t>(y));
    if (settings_.disp12MaxDiff < 0) return;
    kernels_.leftRightRow(s.best.data(), s.bestSum.data(), width_, settings_.minDisparity, settings_.disp12MaxDiff,
                          s.rightKey.data(), fixed_.ptr<uint16_t>(y));
}

// The path costs of a pass from row to row: each direction has two rows of the stripe's
// scratch (previous, current), swapped after each image row; its first row has no
// predecessors.
class Engine::PathRows {
public:
    // dxs: the column offset of each path's predecessor in the previous row.
    template <size_t N>
    PathRows(const Engine &e, Stripe &s, const int (&dxs)[N])
        : rows_(s.pathRows.data()), mins_(s.pathMins.data()), width_(static_cast<size_t>(e.width_)),
          stride_(pathStride(e.paddedDisp_)), dxs_(dxs), count_(N) {
        static_assert(N <= kMaxRowPaths, "at most kMaxRowPaths paths a row");
    }
    // The paths of the next row; their costs go to `kept` (a row of the volume the pass up
    // reads) where given, else to the scratch rows.
    RowPaths next(uint8_t *kept = nullptr) {
        RowPaths rp{};
        rp.count = static_cast<int>(count_);
        for (size_t i = 0; i < count_; ++i) {
            rp.dx[i] = dxs_[i];
            rp.prevL[i] = prev_[i];
            rp.prevMin[i] = mins_ + (2 * i + (parity_ ^ 1)) * width_;
            rp.curL[i] = kept ? kept : rows_ + (2 * i + parity_) * width_ * stride_;
            rp.curMin[i] = mins_ + (2 * i + parity_) * width_;
            prev_[i] = rp.curL[i];
        }
        parity_ ^= 1;
        return rp;
    }

private:
    uint8_t *rows_, *mins_;
    size_t width_, stride_;
    const int *dxs_;
    size_t count_, parity_ = 0;
    const uint8_t *prev_[kMaxRowPaths] = {};
};

Engine::Row Engine::rowOf(Stripe &s, int y, int yFirst, bool down) {
    const bool own = y >= s.y0 && y < s.y1;
    const int step = down ? 1 : -1;
    return {y, own, costRow(s, y, own, down), greyLeft_.ptr<uint8_t>(y),
            y == yFirst ? nullptr : greyLeft_.ptr<uint8_t>(y - step)};
}

// Rows y0 .. y1 - 1. The vertical and diagonal paths start kStripeOverlapRows above (and
// for the pass up, below) the stripe, so that they arrive warmed up; rows outside the
// stripe only carry their paths on: no sums, no winner.
void Engine::matchStripe(Stripe &s) {
    const PathParams pp{settings_.p1, p2ByStep_ + 255};
    if (settings_.paths == 4) matchFourPaths(s, pp);
    else if (settings_.paths == 5) matchFivePaths(s, pp);
    else matchEightPaths(s, pp);
}

// 5 paths, one pass down: the horizontal paths store a row of sums, the three from above
// add to it, then the winner.
void Engine::matchFivePaths(Stripe &s, const PathParams &pp) {
    PathRows paths(*this, s, kVerticalAndDiagonals);
    for (int y = s.first; y < s.y1; ++y) {
        const Row r = rowOf(s, y, s.first, true);
        uint16_t *sum = r.own ? s.scratchSum.data() : nullptr;
        if (sum) kernels_.horizontalRow(r.cost, width_, paddedDisp_, r.grey, pp, s.horizontal.data(), sum, true);
        kernels_.pathRow(r.cost, width_, paddedDisp_, paths.next(), r.grey, r.greyPrev, pp, sum, false);
        if (sum) finishRow(s, sum, y);
    }
}

// 8 paths: the pass down stores the horizontal paths' sums in the volume and adds the
// three from above; the pass up adds the three from below, then the winner.
void Engine::matchEightPaths(Stripe &s, const PathParams &pp) {
    PathRows down(*this, s, kVerticalAndDiagonals);
    for (int y = s.first; y < s.y1; ++y) {
        const Row r = rowOf(s, y, s.first, true);
        uint16_t *sum = r.own ? volumeRow(y) : nullptr;
        if (sum) kernels_.horizontalRow(r.cost, width_, paddedDisp_, r.grey, pp, s.horizontal.data(), sum, true);
        kernels_.pathRow(r.cost, width_, paddedDisp_, down.next(), r.grey, r.greyPrev, pp, sum, false);
    }
    PathRows up(*this, s, kVerticalAndDiagonals);
    for (int y = s.last - 1; y >= s.y0; --y) {
        const Row r = rowOf(s, y, s.last - 1, false);
        uint16_t *sum = r.own ? volumeRow(y) : nullptr;
        kernels_.pathRow(r.cost, width_, paddedDisp_, up.next(), r.grey, r.greyPrev, pp, sum, false);
        if (sum) finishRow(s, sum, y);
    }
}

// 4 paths: the pass down keeps its costs and its vertical path (8-bit) for the pass up,
// which runs the path from below, the horizontal paths and the winner: for each own row
// one fused kernel adds the four and finds the winner, nothing 16-bit written to a row.
void Engine::matchFourPaths(Stripe &s, const PathParams &pp) {
    PathRows down(*this, s, kVertical);
    for (int y = s.first; y < s.y1; ++y) {
        const Row r = rowOf(s, y, s.first, true);
        kernels_.pathRow(r.cost, width_, paddedDisp_, down.next(r.own ? downPathRow(y) : nullptr), r.grey, r.greyPrev,
                         pp, nullptr, false);
    }
    // The horizontal paths of own rows, kept whole (8-bit) for the fused kernel: those of
    // two rows at once (four serial chains side by side, whose latencies overlap), this
    // row's (0, 1) and the next one's (2, 3) for the next step.
    const size_t row = static_cast<size_t>(width_) * paddedDisp_;
    uint8_t *const h[4] = {s.horizontalPaths.data(), s.horizontalPaths.data() + row,
                           s.horizontalPaths.data() + 2 * row, s.horizontalPaths.data() + 3 * row};
    bool second = false; // this row's horizontal paths were run with the row before
    PathRows up(*this, s, kVertical);
    for (int y = s.last - 1; y >= s.y0; --y) {
        const Row r = rowOf(s, y, s.last - 1, false);
        const RowPaths paths = up.next();
        if (!r.own) {
            kernels_.pathRow(r.cost, width_, paddedDisp_, paths, r.grey, r.greyPrev, pp, nullptr, false);
            continue;
        }
        const bool pair = !second && y - 1 >= s.y0;
        if (!second) {
            const uint8_t *costs[2] = {r.cost, pair ? costRow(s, y - 1, true, false) : nullptr};
            const uint8_t *greys[2] = {r.grey, greyLeft_.ptr<uint8_t>(pair ? y - 1 : y)};
            uint8_t *const forwards[2] = {h[0], h[2]}, *const backwards[2] = {h[1], h[3]};
            kernels_.horizontalPaths(costs, pair ? 2 : 1, width_, paddedDisp_, greys, pp, s.horizontal.data(),
                                     forwards, backwards);
        }
        kernels_.upWtaRow(r.cost, width_, paddedDisp_, paths, r.grey, r.greyPrev, pp, downPathRow(y),
                          h[second ? 2 : 0], h[second ? 3 : 1], wtaParams(), s.best.data(), s.bestSum.data(),
                          fixed_.ptr<uint16_t>(y));
        finishRow(s, nullptr, y);
        second = pair;
    }
}

void Engine::medianRow(Stripe &s, int y, cv::Mat &disparity, float invalid) {
    const int size = settings_.medianPx, k = size / 2;
    const uint16_t *rows[kMaxMedianPx];
    for (int j = 0; j < size; ++j) rows[j] = fixed_.ptr<uint16_t>(std::clamp(y + j - k, 0, height_ - 1));
    kernels_.medianRow(rows, width_, size, s.medianScratch.data(), invalid, disparity.ptr<float>(y));
}

// A small median removes isolated outliers; an invalid pixel (0) among valid ones is
// outvoted, a valid one among invalid ones is dropped. A stripe filters the rows whose
// window lies in its own rows (or beyond the image); the medianPx / 2 rows on either side
// of a border between stripes wait for both (they are filtered once all stripes are
// done), so the result is that of one median over the whole image.
void Engine::runStripe(Stripe &s, cv::Mat *disparity, float invalid) {
    censusOf(s);
    matchStripe(s);
    if (!disparity) return;
    const int k = settings_.medianPx / 2;
    const int from = s.y0 == 0 ? 0 : s.y0 + k, to = s.y1 == height_ ? height_ : s.y1 - k;
    for (int y = from; y < to; ++y) medianRow(s, y, *disparity, invalid);
}

// One parallel loop a pair (one wait for the slowest thread): each stripe whole in a task.
void Engine::run(const cv::Mat &left, const cv::Mat &right, cv::Mat *disparity, float invalid) {
    CV_Assert(left.type() == CV_8UC1 && right.type() == CV_8UC1 && left.size() == right.size());
    prepare(left.cols, left.rows);
    greyLeft_ = left;
    greyRight_ = right;
    const int n = static_cast<int>(stripes_.size());
    cv::parallel_for_(cv::Range(0, n), [&](const cv::Range &range) {
        for (int i = range.start; i < range.end; ++i) runStripe(stripes_[static_cast<size_t>(i)], disparity, invalid);
    });
    if (!disparity) return;
    const int k = settings_.medianPx / 2;
    for (int i = 1; i < n; ++i) {
        const int border = stripes_[static_cast<size_t>(i)].y0;
        for (int y = std::max(0, border - k); y < std::min(height_, border + k); ++y)
            medianRow(stripes_[0], y, *disparity, invalid);
    }
    if (settings_.fillDense) filler_.fill(*disparity, invalid, kOcclusionJumpPx, filled_);
}

const cv::Mat &Engine::computeFixed(const cv::Mat &left, const cv::Mat &right) {
    run(left, right, nullptr, 0.0f);
    return fixed_;
}

void Engine::compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity, float invalid) {
    CV_Assert(disparity.type() == CV_32FC1 && disparity.size() == left.size());
    run(left, right, &disparity, invalid);
}

} // namespace sgm
