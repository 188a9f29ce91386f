// SPDX-License-Identifier: MIT
// The sgm matcher plugin against OpenCV's, all three as built plugins through the host,
// interleaved frame by frame in the same run so that a loaded machine slows them alike:
//  - speed at 640 x 480 (the aloe pair, resized) with 64 and 128 disparities, and on the
//    full-size aloe pair (1282 x 1110, 256 disparities): sgm (its defaults), sgbm in its
//    fastest mode (sgbm_3way, block 5) and bm (block 15); ratios printed as counters;
//  - the same for sgm with `fill: dense` against sgm without it (SgmSpeedDense);
//  - accuracy on the full-size aloe pair against aloeGT.png: bad-2, density, bad-2
//    counting holes as errors, mean end-point error, for the three.
//   build/bench/binocle_bench --benchmark_filter=Sgm
// E1's accuracy comes from `binocle experiment` (plugins/sgm/README.md).
#include "bench_plugins.hpp"
#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

std::unique_ptr<binocle::Matcher> matcher(const std::string &plugin, const std::string &yaml) {
    const binocle::PluginRecord &record = binocle::bench::builtPlugins().require(plugin, BINOCLE_KIND_MATCHER);
    return std::make_unique<binocle::Matcher>(record, binocle::paramsFromYaml(record, yaml));
}

struct Contender {
    const char *label;
    const char *plugin;
    std::string yaml; // num_disparities is appended
};

std::vector<Contender> contenders() {
    return {{"sgm", "sgm", "{"}, {"sgbm_3way", "sgbm", "{mode: sgbm_3way, block_size: 5, "}, {"bm", "bm", "{block_size: 15, "}};
}

bool loadAloe(cv::Mat &left, cv::Mat &right, cv::Mat &truth) {
    const std::string dir = std::string(BINOCLE_OPENCV_DATA_DIR) + "/";
    left = cv::imread(dir + "aloeL.jpg", cv::IMREAD_GRAYSCALE);
    right = cv::imread(dir + "aloeR.jpg", cv::IMREAD_GRAYSCALE);
    truth = cv::imread(dir + "aloeGT.png", cv::IMREAD_GRAYSCALE);
    return !left.empty() && !right.empty() && !truth.empty();
}

// The aloe pair at the bench's size: args width (0 = the full-size pair).
bool loadSpeedPair(benchmark::State &state, cv::Mat &left, cv::Mat &right) {
    cv::Mat truth;
    if (!loadAloe(left, right, truth)) {
        state.SkipWithError("the opencv-doc aloe pair is missing");
        return false;
    }
    if (state.range(0) > 0) {
        const cv::Size size(static_cast<int>(state.range(0)), static_cast<int>(state.range(0)) * 3 / 4);
        cv::resize(left, left, size, 0, 0, cv::INTER_AREA);
        cv::resize(right, right, size, 0, 0, cv::INTER_AREA);
    }
    return true;
}

// The contenders interleaved frame by frame (args: width, num_disparities); each one's
// mean time a frame in ms as a counter <label>_ms; returns each one's total seconds.
std::vector<double> timeInterleaved(benchmark::State &state, const std::vector<Contender> &all, const cv::Mat &left,
                                    const cv::Mat &right) {
    const std::string disparities = "num_disparities: " + std::to_string(state.range(1)) + "}";
    std::vector<std::unique_ptr<binocle::Matcher>> matchers;
    for (const Contender &c : all) matchers.push_back(matcher(c.plugin, c.yaml + disparities));
    std::vector<cv::Mat> out(all.size());
    // A first frame each: buffers are made then, not in the timed frames.
    for (size_t i = 0; i < all.size(); ++i) matchers[i]->compute(left, right, out[i]);
    std::vector<double> seconds(all.size(), 0);
    for (auto _ : state) {
        double frame = 0;
        for (size_t i = 0; i < all.size(); ++i) {
            const auto t0 = Clock::now();
            matchers[i]->compute(left, right, out[i]);
            const double s = std::chrono::duration<double>(Clock::now() - t0).count();
            seconds[i] += s;
            frame += s;
        }
        state.SetIterationTime(frame);
    }
    const double n = static_cast<double>(state.iterations());
    for (size_t i = 0; i < all.size(); ++i) state.counters[std::string(all[i].label) + "_ms"] = 1e3 * seconds[i] / n;
    state.SetLabel(std::to_string(left.cols) + "x" + std::to_string(left.rows) + ", " +
                   std::to_string(state.range(1)) + " disparities, " + std::to_string(cv::getNumThreads()) + " threads");
    return seconds;
}

// Args: width (0 = the full-size pair), num_disparities.
void BM_SgmSpeedVersusOpenCv(benchmark::State &state) {
    cv::Mat left, right;
    if (!loadSpeedPair(state, left, right)) return;
    const std::vector<double> seconds = timeInterleaved(state, contenders(), left, right);
    state.counters["sgm_fps_over_sgbm_3way"] = seconds[1] / seconds[0];
    state.counters["sgm_fps_over_bm"] = seconds[2] / seconds[0];
}
BENCHMARK(BM_SgmSpeedVersusOpenCv)->Args({640, 64})->Args({640, 128})->Args({0, 256})
    ->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(3.0);

// sgm with `fill: dense` against sgm without it (its defaults), interleaved: the time of
// a dense frame over a sparse one (issue 34's bar: within 1.10 at 640 x 480 x 128).
void BM_SgmSpeedDense(benchmark::State &state) {
    cv::Mat left, right;
    if (!loadSpeedPair(state, left, right)) return;
    const std::vector<double> seconds =
        timeInterleaved(state, {{"sgm", "sgm", "{"}, {"sgm_dense", "sgm", "{fill: dense, "}}, left, right);
    state.counters["dense_time_over_sgm"] = seconds[1] / seconds[0];
}
BENCHMARK(BM_SgmSpeedDense)->Args({640, 64})->Args({640, 128})
    ->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(3.0);

// Full-size aloe, 256 disparities (configs/rigs/opencv-aloe.yaml's): each matcher scored as
// the `disparity` evaluator scores it (truth 0 = unknown; a hole is a pixel <= 0).
void BM_SgmAccuracyOnAloe(benchmark::State &state) {
    cv::Mat left, right, truth;
    if (!loadAloe(left, right, truth)) {
        state.SkipWithError("the opencv-doc aloe pair is missing");
        return;
    }
    std::vector<Contender> all = contenders();
    for (auto _ : state) {
        for (const Contender &c : all) {
            const cv::Mat d = matcher(c.plugin, c.yaml + "num_disparities: 256}")->compute(left, right);
            double known = 0, matched = 0, bad = 0, error = 0;
            for (int v = 0; v < d.rows; ++v)
                for (int u = 0; u < d.cols; ++u) {
                    const int t = truth.at<uint8_t>(v, u);
                    if (t == 0) continue;
                    ++known;
                    const float x = d.at<float>(v, u);
                    if (!(x > 0)) continue;
                    ++matched;
                    error += std::fabs(x - t);
                    bad += std::fabs(x - t) > 2;
                }
            const std::string l = c.label;
            state.counters[l + "_bad2_percent"] = 100 * bad / matched;
            state.counters[l + "_density_percent"] = 100 * matched / known;
            state.counters[l + "_bad2_holes_percent"] = 100 * (bad + known - matched) / known;
            state.counters[l + "_epe_px"] = error / matched;
        }
    }
}
BENCHMARK(BM_SgmAccuracyOnAloe)->Iterations(1)->Unit(benchmark::kMillisecond);

} // namespace
