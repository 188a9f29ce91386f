// SPDX-License-Identifier: MIT
// sgm: the matching of one pair: census of both images, then per stripe of rows the
// costs, the path aggregation (one pass down, and for 4 and 8 paths one pass up over
// volumes the pass down kept), winner takes all with the left-right check, then a median.
#include "sgm_engine.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace sgm {
namespace {

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
    if (settings_.paths == 4) downDx_ = upDx_ = {0};
    else if (settings_.paths == 5) downDx_ = {-1, 0, 1};
    else downDx_ = upDx_ = {-1, 0, 1};
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
    const double images = 2 * (w + 2 * rx) * (h + 2 * ry) + 2 * w * h * 8 /* census */ + 2 * w * h * 2 /* fixed */;
    const double stripe = w * dp /* cost */ + 6 * w * ds + 6 * w + horizontalScratch(width, paddedDisp_) + w * dp * 4 /* scratch sums */ + 8 * w +
                          8.0 * kernels_.costScratchWords(width, settings_.minDisparity, paddedDisp_);
    const double median = kFinishBands * 2.0 * medianScratch(width);
    return volume + images + std::max(1, settings_.stripes) * stripe + median;
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
    censusLeft_.assign(w * h, 0);
    censusRight_.assign(w * h, 0);
    volume_.assign(twoPass_ && !keepDownPath_ ? w * h * dp : 0, 0);
    // The sentinels at d = -1 and d = Dp of every pixel are written here, once.
    downPath_.assign(keepDownPath_ ? w * h * ds : 0, kCostInvalid);
    costVolume_.assign(twoPass_ ? w * h * dp : 0, 0);
    stripes_.assign(static_cast<size_t>(std::clamp(settings_.stripes, 1, height)), Stripe{});
    for (Stripe &s : stripes_) {
        s.cost.assign(w * dp, kCostInvalid);
        // The sentinels at d = -1 and d = Dp are written here once and never again.
        s.pathRows.assign(6 * w * ds, kCostInvalid);
        s.pathMins.assign(6 * w, 0);
        s.horizontal.assign(horizontalScratch(width, paddedDisp_), kCostInvalid);
        s.scratchSum.assign(2 * w * dp, 0); // two rows: the horizontal paths run two at once
        s.costScratch.assign(kernels_.costScratchWords(width, settings_.minDisparity, paddedDisp_), 0);
        s.best.assign(w, -1);
        s.bestSum.assign(w, 0);
        s.rightKey.assign(w + 1, UINT32_MAX); // and a spare column
    }
    fixed_.create(height, width, CV_16UC1);
    // Bands of the median and conversion, run in parallel: a scratch each.
    bandScratch_.assign(static_cast<size_t>(std::clamp(height / 32, 1, kFinishBands)),
                        AlignedVector<uint16_t>(medianScratch(width), 0));
    ++allocations_;
}

// The census of every row of both images, rows in parallel (one parallel loop: one wait
// for the slowest thread, not two). The images are first padded by replication so that
// the window never leaves them.
void Engine::census(const cv::Mat &left, const cv::Mat &right) {
    const int rx = settings_.censusWidth / 2, ry = settings_.censusHeight / 2;
    cv::copyMakeBorder(left, paddedLeft_, ry, ry, rx, rx, cv::BORDER_REPLICATE);
    cv::copyMakeBorder(right, paddedRight_, ry, ry, rx, rx, cv::BORDER_REPLICATE);
    cv::parallel_for_(cv::Range(0, 2 * height_), [&](const cv::Range &range) {
        const uint8_t *rows[16];
        for (int i = range.start; i < range.end; ++i) {
            const bool isLeft = i < height_;
            const int y = isLeft ? i : i - height_;
            const cv::Mat &padded = isLeft ? paddedLeft_ : paddedRight_;
            for (int j = 0; j < settings_.censusHeight; ++j) rows[j] = padded.ptr<uint8_t>(y + j) + rx;
            kernels_.censusRow(rows, width_, settings_.censusWidth, settings_.censusHeight, settings_.censusSymmetric,
                               (isLeft ? censusLeft_ : censusRight_).data() + static_cast<size_t>(y) * width_);
        }
    });
}

const uint8_t *Engine::costRow(Stripe &s, int y, bool own, bool down) {
    const size_t at = static_cast<size_t>(y) * width_;
    uint8_t *volumeRow = twoPass_ && own ? costVolume_.data() + at * paddedDisp_ : nullptr;
    if (volumeRow && !down) return volumeRow; // computed by this stripe's pass down
    uint8_t *out = volumeRow ? volumeRow : s.cost.data();
    // Words of at most 32 bits (the default centre-symmetric 9 x 7: 31) on 32-bit lanes.
    const bool narrow = censusBits(settings_.censusWidth, settings_.censusHeight, settings_.censusSymmetric) <= 32;
    const CostRowFn kernel = narrow ? kernels_.costRow32 : kernels_.costRow;
    kernel(censusLeft_.data() + at, censusRight_.data() + at, width_, settings_.minDisparity, settings_.numDisparities,
           paddedDisp_, s.costScratch.data(), out);
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

// Rows y0 .. y1 - 1. The vertical and diagonal paths start kStripeOverlapRows above (and
// for the pass up, below) the stripe, so that they arrive warmed up; the sums of those
// rows go to scratch.
void Engine::matchStripe(int index, int y0, int y1) {
    Stripe &s = stripes_[static_cast<size_t>(index)];
    const size_t w = static_cast<size_t>(width_), ds = pathStride(paddedDisp_);
    const PathParams pp{settings_.p1, p2ByStep_ + 255};
    uint8_t *rowsL = s.pathRows.data();
    uint8_t *mins = s.pathMins.data();
    // Direction i has two rows (previous, current), swapped after each image row.
    auto pathL = [&](size_t dir, int parity) { return rowsL + (2 * dir + parity) * w * ds; };
    auto pathMin = [&](size_t dir, int parity) { return mins + (2 * dir + parity) * w; };

    const uint8_t *prevRowL[kMaxRowPaths] = {};
    auto run = [&](const std::vector<int> &dxs, int yFirst, int yLast, int step, bool down) {
        int parity = 0, pairedRow = -1;
        for (int y = yFirst;; y += step) {
            const bool own = y >= y0 && y < y1;
            const uint8_t *cost = costRow(s, y, own, down);
            // Rows outside the stripe only carry their paths on: no sums.
            uint16_t *sum = nullptr;
            if (own && keepDownPath_) {
                if (!down) { // the horizontal paths first, then this pass's and the kept vertical
                    // Those of two rows at once (four serial chains side by side, whose
                    // latencies overlap): this one's, and the next one's for the next step.
                    uint16_t *second = s.scratchSum.data() + w * paddedDisp_;
                    const int next = y + step;
                    if (y == pairedRow) {
                        sum = second;
                    } else if (y != yLast && next >= y0 && next < y1) {
                        sum = s.scratchSum.data();
                        kernels_.horizontalRows(cost, costRow(s, next, true, false), width_, paddedDisp_,
                                                greyLeft_.ptr<uint8_t>(y), greyLeft_.ptr<uint8_t>(next), pp,
                                                s.horizontal.data(), sum, second);
                        pairedRow = next;
                    } else {
                        sum = s.scratchSum.data();
                        kernels_.horizontalRow(cost, width_, paddedDisp_, greyLeft_.ptr<uint8_t>(y), pp,
                                               s.horizontal.data(), sum, true);
                    }
                }
            } else if (own) {
                // The pass down stores the horizontal paths' sums; the rest add to them (the
                // pass up to the pass down's).
                sum = twoPass_ ? volumeRow(y) : s.scratchSum.data();
                if (down)
                    kernels_.horizontalRow(cost, width_, paddedDisp_, greyLeft_.ptr<uint8_t>(y), pp,
                                           s.horizontal.data(), sum, true);
            }
            const bool first = y == yFirst;
            const bool keep = keepDownPath_ && own && down;
            const uint8_t *greyPrev = first ? nullptr : greyLeft_.ptr<uint8_t>(y - step);
            RowPaths rp{};
            rp.count = static_cast<int>(dxs.size());
            for (size_t i = 0; i < dxs.size(); ++i) {
                rp.dx[i] = dxs[i];
                rp.prevL[i] = first ? nullptr : prevRowL[i];
                rp.prevMin[i] = pathMin(i, parity ^ 1);
                rp.curL[i] = keep ? downPathRow(y) : pathL(i, parity);
                rp.curMin[i] = pathMin(i, parity);
                prevRowL[i] = rp.curL[i];
            }
            if (own && keepDownPath_ && !down) {
                // The vertical path, the sums and the winner in one kernel; then the check.
                kernels_.upWtaRow(cost, width_, paddedDisp_, rp, greyLeft_.ptr<uint8_t>(y), greyPrev, pp,
                                  downPathRow(y), sum, wtaParams(), s.best.data(), s.bestSum.data(),
                                  fixed_.ptr<uint16_t>(y));
                finishRow(s, nullptr, y);
            } else {
                kernels_.pathRow(cost, width_, paddedDisp_, rp, greyLeft_.ptr<uint8_t>(y), greyPrev, pp, sum, false);
                if (own && (down != twoPass_)) finishRow(s, sum, y);
            }
            parity ^= 1;
            if (y == yLast) break;
        }
    };
    run(downDx_, std::max(0, y0 - kStripeOverlapRows), y1 - 1, 1, true);
    if (twoPass_) run(upDx_, std::min(height_ - 1, y1 - 1 + kStripeOverlapRows), y0, -1, false);
}

const cv::Mat &Engine::computeFixed(const cv::Mat &left, const cv::Mat &right) {
    CV_Assert(left.type() == CV_8UC1 && right.type() == CV_8UC1 && left.size() == right.size());
    prepare(left.cols, left.rows);
    greyLeft_ = left;
    greyRight_ = right;
    census(left, right);
    const int n = static_cast<int>(stripes_.size());
    cv::parallel_for_(cv::Range(0, n), [&](const cv::Range &range) {
        for (int i = range.start; i < range.end; ++i)
            matchStripe(i, height_ * i / n, height_ * (i + 1) / n);
    });
    return fixed_;
}

void Engine::compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity, float invalid) {
    CV_Assert(disparity.type() == CV_32FC1 && disparity.size() == left.size());
    computeFixed(left, right);
    // A small median removes isolated outliers; an invalid pixel (0) among valid ones
    // is outvoted, a valid one among invalid ones is dropped. Median and conversion run
    // in bands of rows in parallel (in one thread they were a tenth of the frame's time
    // on 2 threads); each row's median reads the rows around it, the image's first and
    // last rows repeated beyond it, so the result is that of the whole image.
    const int size = settings_.medianPx, k = size / 2, bands = static_cast<int>(bandScratch_.size());
    cv::parallel_for_(cv::Range(0, bands), [&](const cv::Range &range) {
        for (int i = range.start; i < range.end; ++i) {
            const int y0 = height_ * i / bands, y1 = height_ * (i + 1) / bands;
            for (int y = y0; y < y1; ++y) {
                const uint16_t *rows[kMaxMedianPx];
                for (int j = 0; j < size; ++j) rows[j] = fixed_.ptr<uint16_t>(std::clamp(y + j - k, 0, height_ - 1));
                kernels_.medianRow(rows, width_, size, bandScratch_[static_cast<size_t>(i)].data(), invalid,
                                   disparity.ptr<float>(y));
            }
        }
    });
}

} // namespace sgm
