// SPDX-License-Identifier: MIT
// The references the benchmarks measure Binocle's cloud stage against: what a user writes
// without Binocle after cv::reprojectImageTo3D.
#pragma once

#include <opencv2/core.hpp>

namespace binocle::bench {

// Each pixel of `xyz` (cv::reprojectImageTo3D of `disparity`, CV_32FC3) with a positive
// disparity and a depth in (0, maxRangeMm], handed to `keep(u, v, point)`.
template <class Keep> void forEachValidPoint(const cv::Mat &disparity, const cv::Mat &xyz, double maxRangeMm, Keep keep) {
    for (int v = 0; v < xyz.rows; ++v) {
        const float *d = disparity.ptr<float>(v);
        const cv::Vec3f *p = xyz.ptr<cv::Vec3f>(v);
        for (int u = 0; u < xyz.cols; ++u) {
            if (!(d[u] > 0) || !(p[u][2] > 0) || p[u][2] > maxRangeMm) continue;
            keep(u, v, p[u]);
        }
    }
}

} // namespace binocle::bench
