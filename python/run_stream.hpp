// SPDX-License-Identifier: MIT
// A rig's pipeline run on a thread of its own, handing each finished frame (owned copies
// of its images and cloud) to one consumer through a bounded queue; no Python here.
#pragma once

#include "app/run_rig.hpp"
#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"
#include "pipeline/pipeline.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

namespace binocle::python {

// A rig as loaded (the same loadRig and --set checks as `binocle run`), with the plugin
// host its records belong to: shared by the Rig object and every run made from it.
struct LoadedRig {
    std::unique_ptr<PluginHost> host;
    RigConfig rig;
};

// One frame, owned: what FrameResult lends for the duration of a call, copied once on
// the pipeline's writer stage (its pooled buffers are reused by later frames).
struct OwnedFrame {
    uint64_t index = 0, sequence = 0;
    cv::Mat left, right; // rectified, GRAY8 or BGR8
    cv::Mat disparity;   // CV_32F, invalid <= 0
    std::vector<float> xyz; // 3 per point, mm
    std::vector<uint8_t> rgb; // 3 per point (R, G, B), or empty
    int32_t cloud_frame = 0;
    double valid_pixel_ratio = 0, seconds = 0, latency_s = 0;
    nlohmann::ordered_json metrics; // {evaluator: {metric: value}}
    std::vector<std::pair<std::string, double>> figures; // "evaluator.metric"
};

struct StreamOptions {
    int64_t max_frames = -1;
    std::string out_dir; // empty: nothing written
    bool force = false;  // --force of `binocle run`
    bool progress = false;
    size_t depth = 4;    // frames waiting for the consumer
};

// Starts the run at construction. The consumer calls next(); stop() (or the destructor)
// asks the run to stop as SIGINT does for `binocle run`: acquisition ends, the frames in
// flight are finished (and written), the summary says `interrupted`.
class RunStream {
public:
    RunStream(std::shared_ptr<const LoadedRig> rig, const StreamOptions &options);
    ~RunStream();
    RunStream(const RunStream &) = delete;
    RunStream &operator=(const RunStream &) = delete;

    enum class Next { Frame, Waiting, End };
    // Waits up to `wait` for a frame. End: the run is over and every frame was taken, or
    // it was stopped; the run's error, if it failed, is rethrown by finish(). Safe from
    // several threads (each frame goes to one), as stop() and finish() are.
    Next next(std::shared_ptr<OwnedFrame> &frame, std::chrono::milliseconds wait);
    void stop();
    // Waits for the run's thread; rethrows its error (binocle::Error) once, to one caller.
    void finish();
    // The run's summary (as summary.json), once finish() returned; null before.
    nlohmann::ordered_json summary() const;

private:
    void work();
    void onFrame(const FrameResult &r);

    std::shared_ptr<const LoadedRig> rig_;
    StreamOptions options_;
    std::unique_ptr<app::RigRun> run_; // the pipeline and the output folder
    std::atomic<bool> stop_{false};
    mutable std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::shared_ptr<OwnedFrame>> queue_;
    bool done_ = false;
    std::mutex joining_; // finish(): one thread joins, the others wait for it
    bool joined_ = false;
    std::exception_ptr error_;
    nlohmann::ordered_json summary_;
    std::thread thread_;
};

} // namespace binocle::python
