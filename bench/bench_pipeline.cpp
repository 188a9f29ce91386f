// SPDX-License-Identifier: MIT
// The stage pipeline against a plain serial OpenCV loop doing the same steps on the same
// 640 x 480 pair (the opencv-doc aloe pair, resized), in the same run:
//   read both images -> remap -> StereoBM (64 disparities, block 15) or StereoSGBM (64,
//   block 5) -> reprojectImageTo3D -> drop invalid points, R1^T, Eq. 1 -> three density grids
// and the pipeline with replay (loop) | bm or sgbm | ground | density_grids, no outputs.
//   build/bench/binocle_bench --benchmark_filter=PipelineVersusSerial
// A replay soak at 320 x 240 reports the resident memory after 1 000 frames and at the last
// frame (both while the pipeline runs; rss_growth_after_1000_MiB is their difference)
// (BINOCLE_SOAK_FRAMES, default 100 000; minutes):
//   build/bench/binocle_bench --benchmark_filter=ReplaySoak
#include "bench_plugins.hpp"
#include "config/rig_config.hpp"
#include "core/calibration.hpp"
#include "method/density_grid.hpp"
#include "pipeline/pipeline.hpp"
#include "reference_cloud.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

constexpr double kCameraHeightMm = 1500, kInclinationDeg = 10, kMaxRangeMm = 50000;

// The aloe pair at a given size, grey, as PNG files, with a calibration whose maps the
// pipeline and the loop both apply (rectified: 0, so that remap really runs).
struct Pair {
    std::string dir, left, right, calibration;
    binocle::StereoCalibration cal;
};

// Removes the pairs' folders when the benchmark ends.
struct Pairs : std::map<std::pair<int, int>, Pair> {
    ~Pairs() {
        std::error_code ec;
        for (const auto &kv : *this) fs::remove_all(kv.second.dir, ec);
    }
};

const Pair &pairAt(cv::Size size) {
    static Pairs made;
    auto key = std::make_pair(size.width, size.height);
    if (auto it = made.find(key); it != made.end()) return it->second;
    Pair p;
    p.dir = (fs::temp_directory_path() / ("binocle-bench-" + std::to_string(::getpid()) + "-" + std::to_string(size.width))).string();
    fs::create_directories(p.dir);
    const std::string data = BINOCLE_OPENCV_DATA_DIR;
    cv::Mat l = cv::imread(data + "/aloeL.jpg", cv::IMREAD_GRAYSCALE), r = cv::imread(data + "/aloeR.jpg", cv::IMREAD_GRAYSCALE);
    if (l.empty() || r.empty()) throw std::runtime_error("the opencv-doc aloe pair is missing in " + data);
    cv::resize(l, l, size, 0, 0, cv::INTER_AREA);
    cv::resize(r, r, size, 0, 0, cv::INTER_AREA);
    p.left = p.dir + "/left_000.png";
    p.right = p.dir + "/right_000.png";
    cv::imwrite(p.left, l);
    cv::imwrite(p.right, r);
    // Middlebury's f = 3740 px at 1282 px wide, B = 160 mm.
    p.cal = binocle::StereoCalibration::ideal(size, 3740.0 * size.width / 1282.0, 160);
    p.cal.rectified = false;
    p.cal.computeRectification();
    p.calibration = p.dir + "/calibration.yml";
    p.cal.save(p.calibration);
    return made.emplace(key, p).first->second;
}

binocle::RigConfig rigFor(const Pair &p, bool sgbm, int matchers, bool grids, int disparities = 64) {
    std::string y = "name: bench\nsource:\n  plugin: replay\n  layout: glob\n  left: " + p.left + "\n  right: " + p.right +
                    "\n  color: gray\n  loop: true\ncalibration: " + p.calibration + "\n";
    const std::string n = std::to_string(disparities);
    y += sgbm ? "matcher:\n  plugin: sgbm\n  num_disparities: " + n + "\n  block_size: 5\n"
              : "matcher:\n  plugin: bm\n  num_disparities: " + n + "\n  block_size: 15\n";
    y += "transforms:\n  - plugin: ground\n    camera_height_mm: " + std::to_string(kCameraHeightMm) +
         "\n    inclination_deg: " + std::to_string(kInclinationDeg) + "\n";
    if (grids) y += "evaluators:\n  - plugin: density_grids\n";
    y += "outputs: {disparity_png: false, disparity_color: false, cloud_ply: false, max_range_mm: " + std::to_string(kMaxRangeMm) + "}\n";
    y += "runtime:\n  matcher_instances: " + std::to_string(matchers) + "\n";
    return binocle::rigFromNode(YAML::Load(y), p.dir + "/rig.yaml", binocle::bench::builtAndBenchPlugins());
}

// What a user would write without Binocle, one frame after the other.
class SerialLoop {
public:
    SerialLoop(const Pair &p, bool sgbm) : p_(p) {
        const cv::Size size = p.cal.image_size;
        cv::initUndistortRectifyMap(p.cal.M1, p.cal.D1, p.cal.R1, p.cal.P1, size, CV_32FC1, m1x_, m1y_);
        cv::initUndistortRectifyMap(p.cal.M2, p.cal.D2, p.cal.R2, p.cal.P2, size, CV_32FC1, m2x_, m2y_);
        if (sgbm) {
            matcher_ = cv::StereoSGBM::create(0, 64, 5, 8 * 25, 32 * 25, 1, 31, 10, 100, 2, cv::StereoSGBM::MODE_SGBM);
        } else {
            auto bm = cv::StereoBM::create(64, 15);
            bm->setPreFilterCap(31);
            bm->setUniquenessRatio(10);
            bm->setSpeckleWindowSize(100);
            bm->setSpeckleRange(2 * 16);
            bm->setDisp12MaxDiff(1);
            bm->setTextureThreshold(10);
            matcher_ = bm;
        }
        cv::Mat r1;
        p.cal.R1.convertTo(r1, CV_64F);
        R1t_ = cv::Matx33d(r1.reshape(1, 1).ptr<double>()).t();
        const double t = kInclinationDeg * CV_PI / 180;
        sin_ = std::sin(t);
        cos_ = std::cos(t);
    }
    // One frame; adds each step's seconds to `steps` (read, remap, match, reproject, filter + Eq. 1, grids).
    int64_t frame(double steps[6]) {
        auto t0 = Clock::now();
        const cv::Mat l = cv::imread(p_.left, cv::IMREAD_GRAYSCALE), r = cv::imread(p_.right, cv::IMREAD_GRAYSCALE);
        steps[0] += since(t0);
        t0 = Clock::now();
        cv::remap(l, rl_, m1x_, m1y_, cv::INTER_LINEAR);
        cv::remap(r, rr_, m2x_, m2y_, cv::INTER_LINEAR);
        steps[1] += since(t0);
        t0 = Clock::now();
        matcher_->compute(rl_, rr_, fixed_);
        fixed_.convertTo(disparity_, CV_32F, 1.0 / 16);
        steps[2] += since(t0);
        t0 = Clock::now();
        cv::reprojectImageTo3D(disparity_, xyz_, p_.cal.Q, true);
        steps[3] += since(t0);
        t0 = Clock::now();
        points_.clear();
        binocle::bench::forEachValidPoint(disparity_, xyz_, kMaxRangeMm, [&](int, int, const cv::Vec3f &q) {
            const cv::Vec3d c = R1t_ * cv::Vec3d(q[0], q[1], q[2]);
            // Eq. 1
            points_.push_back(static_cast<float>(c[0]));
            points_.push_back(static_cast<float>(c[2] * cos_ - c[1] * sin_));
            points_.push_back(static_cast<float>(kCameraHeightMm - c[2] * sin_ - c[1] * cos_));
        });
        steps[4] += since(t0);
        t0 = Clock::now();
        const binocle::method::DensityGrids g = binocle::method::binCloud(binocle::method::CloudView(points_), spec_);
        steps[5] += since(t0);
        return g.top.total();
    }

private:
    const Pair &p_;
    cv::Mat m1x_, m1y_, m2x_, m2y_, rl_, rr_, fixed_, disparity_, xyz_;
    cv::Ptr<cv::StereoMatcher> matcher_;
    cv::Matx33d R1t_;
    double sin_ = 0, cos_ = 1;
    std::vector<float> points_;
    binocle::method::GridSpec spec_;
};

// Args: matcher (0 bm, 1 sgbm), matcher instances of the pipeline. Each iteration runs
// the serial loop and the pipeline over the same number of frames.
void BM_PipelineVersusSerial(benchmark::State &state) {
    const bool sgbm = state.range(0) == 1;
    const int matchers = static_cast<int>(state.range(1));
    const int frames = sgbm ? 30 : 60;
    const Pair &p = pairAt(cv::Size(640, 480));
    SerialLoop loop(p, sgbm);
    double serial = 0, pipeline = 0, steps[6] = {};
    int64_t serialFrames = 0, pipelineFrames = 0, check = 0;
    for (auto _ : state) {
        auto t0 = Clock::now();
        for (int i = 0; i < frames; ++i) check += loop.frame(steps);
        serial += since(t0);
        serialFrames += frames;
        binocle::Pipeline pipe(rigFor(p, sgbm, matchers, true), binocle::bench::builtAndBenchPlugins());
        binocle::RunOptions o;
        o.max_frames = frames;
        o.progress = false;
        t0 = Clock::now();
        const nlohmann::ordered_json summary = pipe.run(o);
        pipeline += since(t0);
        pipelineFrames += summary["frame_count"].get<int64_t>();
        state.SetIterationTime(since(t0));
    }
    benchmark::DoNotOptimize(check);
    const double sfps = serialFrames / serial, pfps = pipelineFrames / pipeline;
    state.counters["serial_fps"] = sfps;
    state.counters["pipeline_fps"] = pfps;
    state.counters["pipeline_over_serial"] = pfps / sfps;
    const char *names[6] = {"serial_read_ms", "serial_remap_ms", "serial_match_ms", "serial_reproject_ms", "serial_filter_eq1_ms",
                            "serial_grids_ms"};
    for (int i = 0; i < 6; ++i) state.counters[names[i]] = 1e3 * steps[i] / static_cast<double>(serialFrames);
    state.counters["threads"] = cv::getNumThreads();
}
BENCHMARK(BM_PipelineVersusSerial)
    ->ArgNames({"sgbm", "matchers"})
    ->ArgsProduct({{0, 1}, {1, 2}}) // OpenCV SGBM or BM, one or two matchers: the four pairs
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

int64_t residentKiB() {
    std::ifstream statm("/proc/self/statm");
    int64_t size = 0, resident = 0;
    statm >> size >> resident;
    return resident * ::sysconf(_SC_PAGESIZE) / 1024;
}

// Replay of one 320 x 240 pair, looped, through bm (32 disparities, two instances) |
// ground | density_grids with frames.jsonl written: resident memory must stay flat.
void BM_ReplaySoak(benchmark::State &state) {
    const char *env = std::getenv("BINOCLE_SOAK_FRAMES");
    const int64_t frames = env ? std::atoll(env) : 100000;
    const Pair &p = pairAt(cv::Size(320, 240));
    const std::string out = p.dir + "/soak";
    for (auto _ : state) {
        binocle::Pipeline pipe(rigFor(p, false, 2, true, 32), binocle::bench::builtAndBenchPlugins());
        binocle::RunOptions o;
        o.max_frames = frames;
        o.progress = false;
        o.out_dir = out;
        int64_t at1000 = 0, atLast = 0, start = residentKiB();
        const auto t0 = Clock::now();
        // Both figures are taken while the pipeline runs (its pools and threads alive), so
        // they compare like with like; the figure after run() returns is given apart.
        pipe.run(o, [&](const binocle::FrameResult &r) {
            if (r.index == 999) at1000 = residentKiB();
            if (r.index == static_cast<uint64_t>(frames - 1)) atLast = residentKiB();
        });
        const double seconds = since(t0);
        const int64_t end = residentKiB();
        state.SetIterationTime(seconds);
        state.counters["frames"] = static_cast<double>(frames);
        state.counters["fps"] = frames / seconds;
        state.counters["rss_start_MiB"] = start / 1024.0;
        state.counters["rss_1000_MiB"] = at1000 / 1024.0;
        state.counters["rss_last_frame_MiB"] = atLast / 1024.0;
        state.counters["rss_after_run_MiB"] = end / 1024.0;
        state.counters["rss_growth_after_1000_MiB"] = (atLast - at1000) / 1024.0;
    }
    fs::remove_all(out);
}
BENCHMARK(BM_ReplaySoak)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);

} // namespace
