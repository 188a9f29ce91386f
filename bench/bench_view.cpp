// SPDX-License-Identifier: MIT
// What `binocle view` adds per displayed frame, against what the pipeline spends per frame,
// on the simulated rig (configs/rigs/sim-videre.yaml), in the same run:
//   - ViewerPipelineFrame: one frame through the whole stage pipeline (wall time per frame)
//   - ViewerCopyFrame: the observer's copy on the writer stage (the only work a displayed
//     frame costs the pipeline's own threads)
//   - ViewerEncodeFrame: the encoder thread's message (images, density views, cloud)
//   build/bench/binocle_bench --benchmark_filter=Viewer
// The whole loop with a real browser is bench/view_overhead.py.
#include "bench_plugins.hpp"
#include "config/rig_config.hpp"
#include "pipeline/pipeline.hpp"
#include "viewer/frame_snapshot.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>

namespace {

using Clock = std::chrono::steady_clock;

binocle::RigConfig simRig() {
    return binocle::loadRig(std::string(BINOCLE_SOURCE_DIR) + "/configs/rigs/sim-videre.yaml",
                            {binocle::Override::parse("outputs.disparity_png=false"),
                             binocle::Override::parse("outputs.disparity_color=false"),
                             binocle::Override::parse("outputs.cloud_ply=false")},
                            binocle::bench::builtPlugins());
}

// One frame of the simulated rig as the viewer holds it.
const binocle::viewer::FrameProducts &simFrame() {
    static const binocle::viewer::FrameProducts frame = [] {
        binocle::Pipeline pipeline(simRig(), binocle::bench::builtPlugins());
        binocle::RunOptions o;
        o.max_frames = 3;
        o.progress = false;
        binocle::viewer::FrameProducts p;
        pipeline.run(o, [&](const binocle::FrameResult &r) { p = binocle::viewer::copyFrame(r); });
        p.disparity_range = pipeline.matcherDisparityRange();
        p.focal_length_px = pipeline.calibration().focalLengthPx();
        p.baseline_mm = pipeline.calibration().baselineMm();
        return p;
    }();
    return frame;
}

void BM_ViewerPipelineFrame(benchmark::State &state) {
    binocle::Pipeline pipeline(simRig(), binocle::bench::builtPlugins());
    for (auto _ : state) {
        binocle::RunOptions o;
        o.max_frames = 20;
        o.progress = false;
        const auto t0 = Clock::now();
        pipeline.run(o);
        state.SetIterationTime(std::chrono::duration<double>(Clock::now() - t0).count() / 20);
    }
}
BENCHMARK(BM_ViewerPipelineFrame)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_ViewerCopyFrame(benchmark::State &state) {
    const binocle::FrameResult &r = simFrame().result;
    for (auto _ : state) benchmark::DoNotOptimize(binocle::viewer::copyFrame(r));
}
BENCHMARK(BM_ViewerCopyFrame)->Unit(benchmark::kMillisecond);

void BM_ViewerEncodeFrame(benchmark::State &state) {
    const binocle::viewer::FrameProducts &p = simFrame();
    binocle::viewer::EncodeOptions o;
    size_t bytes = 0;
    for (auto _ : state) bytes = binocle::viewer::encodeFrame(p, o).size();
    state.counters["message_kB"] = static_cast<double>(bytes) / 1000;
}
BENCHMARK(BM_ViewerEncodeFrame)->Unit(benchmark::kMillisecond);

} // namespace
