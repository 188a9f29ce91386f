// SPDX-License-Identifier: MIT
// The cloud stage (CloudProjector: valid pixels only, row-constant terms, pooled arrays)
// against cv::reprojectImageTo3D followed by a pass that keeps the valid points, on the
// same 640 x 480 disparity of the aloe pair (StereoBM, 64 disparities), in the same run.
//   build/bench/binocle_bench --benchmark_filter=CloudStage
#include "core/calibration.hpp"
#include "core/cloud.hpp"
#include "reference_cloud.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void BM_CloudStageVersusReproject(benchmark::State &state) {
    const cv::Size size(640, 480);
    const std::string data = BINOCLE_OPENCV_DATA_DIR;
    cv::Mat l = cv::imread(data + "/aloeL.jpg", cv::IMREAD_GRAYSCALE), r = cv::imread(data + "/aloeR.jpg", cv::IMREAD_GRAYSCALE);
    if (l.empty() || r.empty()) {
        state.SkipWithError("the opencv-doc aloe pair is missing");
        return;
    }
    cv::resize(l, l, size, 0, 0, cv::INTER_AREA);
    cv::resize(r, r, size, 0, 0, cv::INTER_AREA);
    cv::Mat fixed, disparity;
    cv::StereoBM::create(64, 15)->compute(l, r, fixed);
    fixed.convertTo(disparity, CV_32F, 1.0 / 16);
    const binocle::StereoCalibration cal = binocle::StereoCalibration::ideal(size, 3740.0 * 640 / 1282, 160);
    const double maxRange = 50000;
    const binocle::CloudProjector projector(cal, maxRange);
    binocle::Cloud cloud;
    cv::Mat xyz;
    std::vector<cv::Point3f> kept;
    std::vector<int32_t> pixels;
    double reproject = 0, stage = 0;
    size_t points = 0;
    for (auto _ : state) {
        auto t0 = Clock::now();
        cv::reprojectImageTo3D(disparity, xyz, cal.Q, true);
        kept.clear();
        pixels.clear();
        binocle::bench::forEachValidPoint(disparity, xyz, maxRange, [&](int u, int v, const cv::Vec3f &p) {
            kept.emplace_back(p[0], p[1], p[2]);
            pixels.push_back(v * xyz.cols + u);
        });
        const double a = since(t0);
        t0 = Clock::now();
        projector.project(disparity, l, cloud); // with the colours, as the pipeline does
        const double b = since(t0);
        benchmark::DoNotOptimize(kept.data());
        benchmark::DoNotOptimize(cloud.xyz.data());
        reproject += a;
        stage += b;
        points = cloud.size();
        state.SetIterationTime(a + b);
    }
    const double n = static_cast<double>(state.iterations());
    state.counters["reproject_filter_ms"] = 1e3 * reproject / n;
    state.counters["cloud_stage_ms"] = 1e3 * stage / n;
    state.counters["speedup"] = reproject / stage;
    state.counters["points"] = static_cast<double>(points);
    state.counters["points_reference"] = static_cast<double>(kept.size());
}
BENCHMARK(BM_CloudStageVersusReproject)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(2.0);

} // namespace
