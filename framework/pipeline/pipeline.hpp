// SPDX-License-Identifier: MIT
// The pipeline of METHOD.md (Fig. 2b): acquire -> rectify -> disparity -> cloud in
// camera coordinates -> cloud transforms (ground frame, Eq. 1) -> evaluators -> outputs,
// run as stages on their own threads joined by bounded queues (README "Runtime").
#pragma once

#include "config/rig_config.hpp"
#include "core/calibration.hpp"
#include "core/cloud.hpp"
#include "host/plugin_host.hpp"
#include "pipeline/frame_writer.hpp"

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace binocle {

class PluginInstances; // pipeline/plugin_instances.hpp, private to the pipeline

struct RunOptions {
    int64_t max_frames = -1;   // frames taken from the source; < 0: until it ends
    std::string out_dir;       // empty: write nothing
    bool progress = true;      // a progress line on stderr
    int32_t grab_timeout_ms = 5000;
    // Polled by the run: once true, acquisition stops, the frames in flight are finished
    // and the summary says `interrupted` (StopSignalGuard::requested() for signals).
    const std::atomic<bool> *stop = nullptr;
    // Called on the acquire stage before a grab, once every frame grabbed so far has
    // been through the writer (onFrame, observers): no stage holds a frame or runs a
    // plugin then, so this is the one place where reconfigure() may run. Returning false
    // ends the run as if the source ended.
    std::function<bool()> between_frames;
    // Null: between_frames runs before every grab, which serialises the stages (one
    // frame in flight). Set: only while it is true (a change or a pause is pending), so
    // the stages run in parallel the rest of the time and drain only when needed.
    const std::atomic<bool> *between_frames_wanted = nullptr;
    // More outputs (a bag), called after the folder's on the writer stage; they must
    // outlive the run (pipeline/frame_writer.hpp).
    std::vector<FrameWriter *> writers;
};

// What one frame produced, for callers that want more than files (experiments, tests,
// viewers). Handed to observers on the writer stage; its images and cloud live in pooled
// buffers that the next frames reuse, so they are valid during the call only.
struct FrameResult {
    uint64_t index = 0;    // 0, 1, 2 ... frames processed in this run (after drops)
    uint64_t sequence = 0; // the source's sequence number
    const LentFrame *frame = nullptr; // as the source lent it (extras, metadata)
    const StereoCalibration *calibration = nullptr; // the run's (focal length, baseline): set on the writer stage
    cv::Mat rectified_left, rectified_right;
    cv::Mat disparity; // CV_32F
    // The planes the matcher attached to it (e.g. "disparity_filled"): handed to evaluators.
    std::vector<NamedPlane> disparity_extras;
    double valid_pixel_ratio = 0; // share of pixels with a disparity
    Cloud cloud;       // after transforms
    nlohmann::ordered_json metrics; // {evaluator: {metric: value}}
    std::vector<std::pair<std::string, double>> figures; // the same, flat: "evaluator.metric"
    double seconds = 0;   // processing time of the frame, all stages added
    double latency_s = 0; // from the grab to the writer stage
    double acquire_seconds = 0; // in the source's grab (a camera's wait for its next image included)
    // Time of each step, in order: rectify, match, cloud, transforms, evaluators.
    std::vector<std::pair<std::string, double>> stage_seconds;
};

// A watcher of a run that must never slow it (a live viewer). `onFrame` is called on the
// writer stage for every finished frame, in frame order, after the outputs are written;
// it must return at once: copy what it needs, or skip the frame. LatestFrame does that.
class FrameObserver {
public:
    virtual ~FrameObserver() = default;
    virtual void onFrame(const FrameResult &frame) = 0;
};

// A copy of what a display needs from one frame.
struct FrameSnapshot {
    uint64_t index = 0, sequence = 0;
    cv::Mat rectified_left, disparity;
    Cloud cloud;
    nlohmann::ordered_json metrics;
};

// Keeps the newest frame for a consumer on another thread. A frame is copied only when
// the consumer has taken the previous copy and is not taking one right now; otherwise
// it is skipped (counted), so a slow consumer costs the run nothing but a try-lock.
class LatestFrame : public FrameObserver {
public:
    void onFrame(const FrameResult &frame) override;
    // The frame copied since the last take, if any. Any thread.
    std::optional<FrameSnapshot> take();
    uint64_t skipped() const { return skipped_.load(); }

private:
    std::mutex mutex_;
    std::optional<FrameSnapshot> slot_;
    std::atomic<uint64_t> skipped_{0};
};


class Pipeline {
public:
    Pipeline(const RigConfig &rig, const PluginHost &host);
    ~Pipeline();

    // Runs and returns the summary (also written as summary.json when out_dir is set,
    // with one line per frame in frames.jsonl). `onFrame` sees every frame, in order, on
    // the calling thread; it may take its time (the stages before it wait, or drop frames
    // under the `latest` policy). Observers (addObserver) must not block.
    // Throws binocle::Error after writing the summary when the run failed.
    nlohmann::ordered_json run(const RunOptions &options, const std::function<void(const FrameResult &)> &onFrame = {});

    // Watches the next runs; the observer must outlive them.
    void addObserver(FrameObserver *observer) { observers_.push_back(observer); }

    // Takes a changed rig between frames (from RunOptions::between_frames): the matcher,
    // transforms, evaluators and source whose block changed are created anew, all before
    // any is swapped in, so a plugin that refuses its settings leaves the pipeline as it
    // was (the PluginError propagates). A new source is started when the old one was.
    void reconfigure(const RigConfig &rig);
    // The matcher's own answer (plugin API), not the rig's value; asked when the matcher
    // is made, so any thread may read it between reconfigure() calls.
    std::pair<int32_t, int32_t> matcherDisparityRange() const { return disparityRange_; }
    // The source's statistics as of its last grab (at most ~0.5 s old): any thread, the
    // source itself is called only from the acquire stage.
    std::string sourceStatistics() const;
    const RigConfig &rig() const { return rig_; }

    const StereoCalibration &calibration() const { return calibration_; }
    Source &source();

private:
    struct Job;
    struct RunState;
    struct EvaluatorSlot;
    void prepareCalibration(const cv::Size &imageSize);
    void acquire(RunState &s);
    void rectifyAndMatch(RunState &s, size_t instance);
    void cloudAndTransforms(RunState &s);
    void evaluate(RunState &s);
    void write(RunState &s, const std::function<void(const FrameResult &)> &onFrame);
    std::string finishSummary(RunState &s, nlohmann::ordered_json &summary, double elapsed);
    void checkFrameSize(const LentFrame &frame, int64_t ordinal) const;
    // runtime.queue_depth frames of the first frame's size must fit in memory.
    void checkQueueMemory(const LentFrame &frame) const;
    void refreshSourceStatistics();
    std::unique_ptr<EvaluatorSlot> makeEvaluator(const PluginBlock &block);

    RigConfig rig_;
    // The plugin instances by wrapper type: one Source, runtime.matcher_instances
    // Matchers, the rig's CloudTransforms and EvaluatorSlots (pipeline_run.hpp), and any
    // other kind's, with no member here for each kind.
    std::unique_ptr<PluginInstances> instances_;
    std::vector<FrameObserver *> observers_;
    bool sourceStarted_ = false;
    std::pair<int32_t, int32_t> disparityRange_{0, 0}; // asked of the matcher when it is made
    mutable std::mutex statisticsMutex_;
    std::string sourceStatistics_; // the source's statistics, refreshed by the acquire stage
    StereoCalibration calibration_;
    std::string calibrationYaml_;
    bool calibrationReady_ = false;
    cv::Size imageSize_; // of the frames the maps were made for
    cv::Mat map1x_, map1y_, map2x_, map2y_;
    CloudProjector projector_;
    std::string outDir_;
};

} // namespace binocle
