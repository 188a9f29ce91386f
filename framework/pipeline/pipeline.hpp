// SPDX-License-Identifier: MIT
// The pipeline of METHOD.md (Fig. 2b): acquire -> rectify -> disparity -> cloud in
// camera coordinates -> cloud transforms (ground frame, Eq. 1) -> evaluators -> outputs.
#pragma once

#include "config/rig_config.hpp"
#include "core/calibration.hpp"
#include "core/cloud.hpp"
#include "core/json.hpp"
#include "host/plugin_host.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace binocle {

struct RunOptions {
    int64_t max_frames = -1;   // < 0: until the source ends
    std::string out_dir;       // empty: write nothing
    bool progress = true;      // a progress line on stderr
    int32_t grab_timeout_ms = 5000;
    // Called on the pipeline's thread before each grab, between frames: the one place
    // where reconfigure() may run. Returning false ends the run as if the source ended.
    std::function<bool()> between_frames;
};

// What one frame produced, for callers that want more than files (experiments, tests).
struct FrameResult {
    uint64_t sequence = 0;
    cv::Mat rectified_left, rectified_right;
    cv::Mat disparity; // CV_32F
    double valid_pixel_ratio = 0; // share of pixels with a disparity
    Cloud cloud;       // after transforms
    Json metrics;      // {evaluator: {metric: value}}
    std::vector<std::pair<std::string, double>> figures; // the same, flat: "evaluator.metric"
    double seconds = 0;
    // Time of each step, in order: rectify, match, cloud, transforms, evaluators.
    std::vector<std::pair<std::string, double>> stage_seconds;
};

// Writes what `outputs` asks for of one frame into `dir` (disparity PNG/PFM, colourised
// disparity, rectified images, cloud PLY), each file atomically; names carry the sequence.
void writeFrameOutputs(const FrameResult &r, const OutputOptions &outputs, const std::string &dir);

class Pipeline {
public:
    Pipeline(const RigConfig &rig, const PluginHost &host);
    ~Pipeline();

    // Runs and returns the summary (also written as summary.json when out_dir is set).
    // `onFrame` sees every frame's result before it is dropped.
    Json run(const RunOptions &options, const std::function<void(const FrameResult &)> &onFrame = {});

    // Takes a changed rig between frames (from RunOptions::between_frames): the matcher,
    // transforms, evaluators and source whose block changed are created anew, all before
    // any is swapped in, so a plugin that refuses its settings leaves the pipeline as it
    // was (the PluginError propagates). A new source is started when the old one was.
    void reconfigure(const RigConfig &rig);
    // The matcher's own answer (plugin API), not the rig's value.
    std::pair<int32_t, int32_t> matcherDisparityRange() { return matcher_->disparityRange(); }
    const RigConfig &rig() const { return rig_; }

    const StereoCalibration &calibration() const { return calibration_; }
    Source &source() { return *source_; }

private:
    struct EvaluatorSlot;
    void prepareCalibration(const cv::Size &imageSize);
    FrameResult process(const LentFrame &frame);
    std::unique_ptr<EvaluatorSlot> makeEvaluator(const PluginBlock &block);

    RigConfig rig_;
    std::unique_ptr<Source> source_;
    std::unique_ptr<Matcher> matcher_;
    std::vector<std::unique_ptr<CloudTransform>> transforms_;
    struct EvaluatorSlot {
        std::string name;
        std::unique_ptr<Evaluator> evaluator;
        Json *target = nullptr; // where its figures go right now
        std::vector<std::pair<std::string, double>> *flat = nullptr;
    };
    std::vector<std::unique_ptr<EvaluatorSlot>> evaluators_;
    bool sourceStarted_ = false;
    StereoCalibration calibration_;
    std::string calibrationYaml_;
    bool calibrationReady_ = false;
    cv::Mat map1x_, map1y_, map2x_, map2y_;
    std::string outDir_;
};

} // namespace binocle
