// SPDX-License-Identifier: MIT
// The cost of `isolation: process` for a matcher at 640 x 480: the same bm matcher (block
// 9, 64 disparities) in process and in its helper process, in the same run. The
// difference per frame is the proxy's price: one copy of the pair into shared memory,
// two messages on a socket, one copy of the disparity out.
// BM_IsolationProxy does the same with the mock_matcher test fixture, which only fills
// the map, so that nearly all of its time is the proxy's. BM_IsolationSource grabs
// 640 x 480 GRAY8 pairs with a FLOAT32 ground-truth plane from the faulty_source fixture
// (fault: none) in process and isolated: the difference is the copy of the frame into
// shared memory in the helper, and a request and a reply on the socket.
//   BINOCLE_PLUGIN_PATH=$PWD/build/test-plugins:$PWD/build/lib/binocle/plugins \
//     build/bench/binocle_bench --benchmark_filter=Isolation
#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

namespace {

struct Fixture {
    binocle::PluginHost host;
    const binocle::PluginRecord *bm = nullptr, *mock = nullptr, *source = nullptr;
    cv::Mat left, right;
    Fixture() {
        bm = host.lookup("bm", BINOCLE_KIND_MATCHER);
        mock = host.lookup("mock_matcher", BINOCLE_KIND_MATCHER);
        source = host.lookup("faulty_source", BINOCLE_KIND_STEREO_SOURCE);
        cv::RNG rng(7);
        left.create(480, 640, CV_8UC1);
        rng.fill(left, cv::RNG::UNIFORM, 0, 256);
        right = cv::Mat::zeros(left.size(), CV_8UC1);
        left.colRange(16, 640).copyTo(right.colRange(0, 624));
    }
};

Fixture &fixture() {
    static Fixture f;
    return f;
}

// Arg: 0 in process, 1 in the helper process.
void run(benchmark::State &state, const binocle::PluginRecord *record, const std::string &settings) {
    Fixture &f = fixture();
    if (!record) {
        state.SkipWithError("plugin not in the search path (mock_matcher: BINOCLE_PLUGIN_PATH=build/test-plugins)");
        return;
    }
    binocle::ParamValues params = binocle::paramsFromYaml(*record, settings);
    binocle::IsolationOptions o;
    o.process = state.range(0) == 1;
    o.call_timeout_ms = 10000;
    binocle::Matcher matcher(*record, params, o);
    for (auto _ : state) {
        cv::Mat d = matcher.compute(f.left, f.right);
        benchmark::DoNotOptimize(d.data);
    }
    state.SetLabel(o.process ? "isolation: process" : "in process");
}

void BM_IsolationBm640x480(benchmark::State &state) { run(state, fixture().bm, "{block_size: 9, num_disparities: 64}"); }
void BM_IsolationProxy640x480(benchmark::State &state) { run(state, fixture().mock, "{}"); }
// Arg: 0 in process, 1 in the helper process.
void BM_IsolationSource640x480(benchmark::State &state) {
    const binocle::PluginRecord *record = fixture().source;
    if (!record) {
        state.SkipWithError("faulty_source not in the search path (BINOCLE_PLUGIN_PATH=build/test-plugins)");
        return;
    }
    binocle::ParamValues params =
        binocle::paramsFromYaml(*record, "{fault: none, frames: 1000000000, width: 640, height: 480}");
    binocle::IsolationOptions o;
    o.process = state.range(0) == 1;
    o.call_timeout_ms = 10000;
    binocle::Source source(*record, params, o);
    source.start();
    for (auto _ : state) {
        std::unique_ptr<binocle::LentFrame> frame = source.grab(1000);
        benchmark::DoNotOptimize(frame->left().data);
    }
    state.SetLabel(o.process ? "isolation: process" : "in process");
}

BENCHMARK(BM_IsolationBm640x480)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IsolationSource640x480)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IsolationProxy640x480)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

} // namespace
