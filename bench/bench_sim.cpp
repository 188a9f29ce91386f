// SPDX-License-Identifier: MIT
// The sim source's renderer against cv::StereoSGBM (128 disparities, block 5) on the
// same 640 x 480 pair, in the same run: the renderer must cost well under the matcher;
// and the occlusion mask's share of a frame.
//   build/bench/binocle_bench --benchmark_filter=Sim
#include "renderer.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>

#include <chrono>
#include <string>
#include <utility>

namespace {

using Clock = std::chrono::steady_clock;

// A 640 x 480 head with the field of view of the 320 x 240 Videre head (10.4 um pixels).
binocle::sim::RigSettings vga() {
    binocle::sim::RigSettings s;
    s.image_width = 640;
    s.image_height = 480;
    s.pixel_pitch_um = 10.4;
    return s;
}

binocle::sim::Scene scene(int which) {
    if (which == 0) return binocle::sim::Scene::builtIn(); // E1 panel
    return binocle::sim::Scene::load(std::string(BINOCLE_SOURCE_DIR) + "/configs/scenes/e2_tree.yaml");
}

cv::Ptr<cv::StereoSGBM> sgbm() { return cv::StereoSGBM::create(0, 128, 5, 8 * 25, 32 * 25, 1, 31, 10, 100, 2); }

// The loop of a benchmark: each iteration renders a frame of `world`, then hands it to
// `after`, both timed; the iteration time is the two. Returns their mean seconds.
template <class After>
std::pair<double, double> renderThen(benchmark::State &state, const binocle::sim::Renderer &renderer,
                                     const binocle::sim::Scene &world, After after) {
    double render = 0, rest = 0;
    uint64_t frame = 0;
    for (auto _ : state) {
        const auto t0 = Clock::now();
        const binocle::sim::RenderedFrame f = renderer.render(world, {}, frame++);
        const auto t1 = Clock::now();
        after(f);
        const auto t2 = Clock::now();
        const double r = std::chrono::duration<double>(t1 - t0).count(), m = std::chrono::duration<double>(t2 - t1).count();
        render += r;
        rest += m;
        state.SetIterationTime(r + m);
    }
    const double n = static_cast<double>(state.iterations());
    return {render / n, rest / n};
}

// Args: scene (0 E1 panel, 1 E2 tree), threads (0: OpenCV's default, else that many).
// Reports render_ms, sgbm_ms and their ratio; iteration time = render + match.
void BM_SimRenderVersusSgbm(benchmark::State &state) {
    const int threads = cv::getNumThreads();
    if (state.range(1) > 0) cv::setNumThreads(static_cast<int>(state.range(1)));
    const binocle::sim::Scene world = scene(static_cast<int>(state.range(0)));
    const binocle::sim::StereoRig rig(vga());
    const binocle::sim::Renderer renderer(rig, binocle::sim::RenderSettings{});
    const cv::Ptr<cv::StereoSGBM> matcher = sgbm();
    cv::Mat disparity;
    const auto [render, match] = renderThen(state, renderer, world, [&](const binocle::sim::RenderedFrame &f) {
        matcher->compute(f.left, f.right, disparity);
        benchmark::DoNotOptimize(disparity.data);
    });
    state.counters["render_ms"] = 1e3 * render;
    state.counters["sgbm_ms"] = 1e3 * match;
    state.counters["render_over_sgbm"] = render / match;
    state.counters["threads"] = cv::getNumThreads();
    cv::setNumThreads(threads);
}
BENCHMARK(BM_SimRenderVersusSgbm)
    ->ArgNames({"scene", "threads"})
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({1, 0})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

// The occlusion mask's share of a frame (gt_nonocc: one shadow ray per known pixel of
// the ground truth, from the right optical centre towards the point the pixel sees).
// One thread, in the same run: render_ms is a whole frame (mask included), mask_ms the
// same tests made again, alone, on that frame's points; mask_over_rest = mask_ms /
// (render_ms - mask_ms), the frame time the mask adds. Arg: scene (0 E1 panel, 1 E2 tree).
void BM_SimOcclusionMaskShare(benchmark::State &state) {
    const int threads = cv::getNumThreads();
    cv::setNumThreads(1);
    const binocle::sim::Scene world = scene(static_cast<int>(state.range(0)));
    const binocle::sim::StereoRig rig(vga());
    const binocle::sim::Renderer renderer(rig, binocle::sim::RenderSettings{});
    const binocle::sim::Tracer tracer(world);
    const binocle::sim::Camera left = rig.rectifiedLeft({}), right = rig.rectifiedRight({});
    const auto [render, mask] = renderThen(state, renderer, world, [&](const binocle::sim::RenderedFrame &f) {
        int seen = 0;
        for (int v = 0; v < f.gt_depth.rows; ++v)
            for (int u = 0; u < f.gt_depth.cols; ++u) {
                const float z = f.gt_depth.at<float>(v, u);
                if (z <= 0) continue;
                const bool ground = f.gt_object_id.at<uint16_t>(v, u) == binocle::sim::Scene::kGroundId;
                seen += binocle::sim::seenBy(right, tracer, left.center + left.direction(u, v) * z, ground);
            }
        benchmark::DoNotOptimize(seen);
    });
    state.counters["render_ms"] = 1e3 * render;
    state.counters["mask_ms"] = 1e3 * mask;
    state.counters["mask_over_rest"] = mask / (render - mask);
    cv::setNumThreads(threads);
}
BENCHMARK(BM_SimOcclusionMaskShare)->ArgName("scene")->Arg(0)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(2.0);

// Loading a scene, noise textures baked (a second load of the same scene reuses them).
void BM_SimLoadScene(benchmark::State &state) {
    for (auto _ : state) benchmark::DoNotOptimize(scene(static_cast<int>(state.range(0))).primitives.size());
}
BENCHMARK(BM_SimLoadScene)->ArgName("scene")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

} // namespace
