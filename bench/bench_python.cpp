// SPDX-License-Identifier: MIT
// The price of a matcher written in Python at 640 x 480: the py_misbehaving fixture with
// its default behaviour (compute returns numpy.zeros: no matching work) against the
// mock_matcher fixture (C++, fills the map: the same no-work) in process, in the same run.
// The difference per frame is the bridge's: the pair copied into arrays Python owns, the
// call with the GIL taken, the result checked (shape, dtype, finite) and copied out.
//   BINOCLE_PLUGIN_PATH=$PWD/build/test-plugins:$PWD/build/test-plugins-python \
//     build/bench/binocle_bench --benchmark_filter=PythonMatcher
#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

namespace {

// Arg: 0 the C++ fixture, 1 the Python one; Arg 2: 1 (GRAY8) or 3 (BGR8) channels.
void BM_PythonMatcher640x480(benchmark::State &state) {
    static binocle::PluginHost host;
    const bool python = state.range(0) == 1;
    const binocle::PluginRecord *record =
        host.lookup(python ? "py_misbehaving" : "mock_matcher", BINOCLE_KIND_MATCHER);
    if (!record) {
        state.SkipWithError("fixture not in the search path (BINOCLE_PLUGIN_PATH=build/test-plugins:build/test-plugins-python)");
        return;
    }
    binocle::Matcher matcher(*record, binocle::paramsFromYaml(*record, "{}"));
    const int type = state.range(1) == 3 ? CV_8UC3 : CV_8UC1;
    cv::Mat left(480, 640, type), right(480, 640, type);
    cv::RNG rng(7);
    rng.fill(left, cv::RNG::UNIFORM, 0, 256);
    rng.fill(right, cv::RNG::UNIFORM, 0, 256);
    for (auto _ : state) {
        cv::Mat d = matcher.compute(left, right);
        benchmark::DoNotOptimize(d.data);
    }
    state.SetLabel(std::string(python ? "python (numpy.zeros)" : "C++ (fills the map)") +
                   (state.range(1) == 3 ? ", BGR8" : ", GRAY8"));
}

} // namespace

BENCHMARK(BM_PythonMatcher640x480)->ArgsProduct({{0, 1}, {1, 3}})->Unit(benchmark::kMicrosecond);
