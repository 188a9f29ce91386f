// SPDX-License-Identifier: MIT
// sgm: census + semi-global matching of a grey pair, on reused buffers. Knows nothing of
// the plugin ABI (the plugin wraps it), so tests can drive it with any kernel table.
#pragma once

#include "sgm_fill.hpp"
#include "sgm_kernels.hpp"

#include <cstddef>
#include <cstdint>
#include <new>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace sgm {

// Buffers on 64-byte boundaries (a cache line, one AVX-512 vector): the kernels' rows of
// whole vectors then never straddle two lines (malloc aligns to 16 only).
template <class T>
struct CacheLineAllocator {
    using value_type = T;
    static constexpr std::align_val_t kAlign{64};
    CacheLineAllocator() = default;
    template <class U>
    CacheLineAllocator(const CacheLineAllocator<U> &) {}
    T *allocate(size_t n) { return static_cast<T *>(::operator new(n * sizeof(T), kAlign)); }
    void deallocate(T *p, size_t) { ::operator delete(p, kAlign); }
    template <class U>
    bool operator==(const CacheLineAllocator<U> &) const { return true; }
    template <class U>
    bool operator!=(const CacheLineAllocator<U> &) const { return false; }
};
template <class T>
using AlignedVector = std::vector<T, CacheLineAllocator<T>>;

struct Settings {
    int minDisparity = 0;
    int numDisparities = 64;
    int censusWidth = 9;
    int censusHeight = 7;
    bool censusSymmetric = false; // centre-symmetric census: half the bits (sgm_kernels.hpp)
    int paths = 4;              // 4 (horizontal + vertical), 5 (one pass), 8
    int p1 = 10;
    int p2 = 120;
    int p2IntensityStep = 30;   // 0: P2 constant; else P2 * s / (s + |intensity step|), >= p1
    int uniquenessPercent = 8;
    int disp12MaxDiff = 1;      // -1: no left-right check
    bool subpixel = true;
    int medianPx = 5;           // 1: none
    int stripes = 2;
    bool fillDense = false;     // fill the invalid pixels after the median (sgm_fill.hpp)
    double maxMemoryBytes = 2048.0 * 1048576.0;
};

// Rows a stripe runs its vertical paths above (and below) its own rows before they count:
// stripes are matched independently, in parallel.
constexpr int kStripeOverlapRows = 16;

class Engine {
public:
    Engine(const Settings &settings, const Kernels &kernels);

    // left, right: CV_8UC1, same size. disparity: CV_32FC1 of that size (may be a view of
    // the caller's buffer): pixels, `invalid` where no match survived the checks.
    void compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity, float invalid);

    // The same, stopping before the median filter and the conversion: (minD + d) * 16,
    // 0 = invalid. For tests.
    const cv::Mat &computeFixed(const cv::Mat &left, const cv::Mat &right);

    // After compute with fillDense: 255 where the value was filled in, 0 where matched
    // (CV_8UC1, the disparity's size); empty without fillDense.
    const cv::Mat &filled() const { return filled_; }

    // Bytes of working memory a width x height pair needs (what max_memory_mb bounds).
    double workingBytes(int width, int height) const;
    // How often the buffers were (re)allocated: once per image size.
    int allocations() const { return allocations_; }
    const Kernels &kernels() const { return kernels_; }

private:
    struct Stripe {
        int y0 = 0, y1 = 0;       // its rows
        int first = 0, last = 0;  // the rows it matches, warm-up included: its census rows
        cv::Mat paddedLeft, paddedRight; // rows first - ry .. last + ry (within the image), padded by rx
        AlignedVector<uint64_t> censusLeft, censusRight; // rows first .. last - 1
        AlignedVector<uint16_t> medianScratch;
        AlignedVector<uint8_t> cost, pathRows, pathMins, horizontal;
        AlignedVector<uint16_t> scratchSum;       // a row of sums (5 paths)
        AlignedVector<uint8_t> horizontalPaths;   // 4 paths: both horizontal paths of two rows
        AlignedVector<uint64_t> costScratch;
        std::vector<int16_t> best;
        std::vector<uint16_t> bestSum;
        std::vector<uint32_t> rightKey; // the left-right check's (sum, d) per right column
    };
    void prepare(int width, int height);
    // One stripe, all of it in one task: the census of its rows (and of the rows its paths
    // warm up on), its matching, and the median of the rows whose window lies in it.
    // disparity NULL: no median.
    void runStripe(Stripe &s, cv::Mat *disparity, float invalid);
    void censusOf(Stripe &s);
    // One row of a pass: whether it is the stripe's own (it counts) or a warm-up row, its
    // costs (costRow), its grey row and the previous one on the pass (none for the first).
    struct Row {
        int y;
        bool own;
        const uint8_t *cost, *grey, *greyPrev;
    };
    class PathRows;
    Row rowOf(Stripe &s, int y, int yFirst, bool down);
    // The paths and the winner of a stripe, one function per path strategy.
    void matchStripe(Stripe &s);
    void matchFourPaths(Stripe &s, const PathParams &pp);
    void matchFivePaths(Stripe &s, const PathParams &pp);
    void matchEightPaths(Stripe &s, const PathParams &pp);
    // The median of row y (its window clamped to the image) and its conversion to pixels.
    void medianRow(Stripe &s, int y, cv::Mat &disparity, float invalid);
    // The whole pair; disparity NULL: no median (computeFixed).
    void run(const cv::Mat &left, const cv::Mat &right, cv::Mat *disparity, float invalid);
    // The costs of row y: computed into the stripe's row (or into the cost volume, for a
    // row of the stripe's own in the pass down), or read back from the volume.
    const uint8_t *costRow(Stripe &s, int y, bool own, bool down);
    // The winner of each pixel of row y from its sums (none: already found by upWtaRow),
    // then the left-right check.
    void finishRow(Stripe &s, const uint16_t *sum, int y);
    WtaParams wtaParams() const {
        return {settings_.minDisparity, settings_.numDisparities, paddedDisp_, settings_.uniquenessPercent,
                settings_.subpixel};
    }
    uint16_t *volumeRow(int y) { return volume_.data() + static_cast<size_t>(y) * width_ * paddedDisp_; }
    uint8_t *downPathRow(int y) {
        return downPath_.data() + static_cast<size_t>(y) * width_ * pathStride(paddedDisp_);
    }

    Settings settings_;
    const Kernels &kernels_;
    int width_ = 0, height_ = 0, paddedDisp_ = 0;
    bool twoPass_ = true;
    bool keepDownPath_ = false; // 4 paths: the pass down keeps its vertical path, not sums
    uint8_t p2ByStep_[511]; // P2 by intensity step -255..255 (PathParams::p2ByStep)
    cv::Mat greyLeft_, greyRight_, fixed_;
    AlignedVector<uint16_t> volume_;  // 8 paths: the pass down's sums
    AlignedVector<uint8_t> downPath_; // 4 paths: the pass down's vertical path (path-row layout)
    AlignedVector<uint8_t> costVolume_; // and its costs, which the pass up reads again
    std::vector<Stripe> stripes_;
    Filler filler_;
    cv::Mat filled_;
    int allocations_ = 0;
};

} // namespace sgm
