// SPDX-License-Identifier: MIT
// The pipeline as stages on their own threads: acquire | rectify + match (one or more
// matcher instances) | cloud + transforms | evaluators | writer (the calling thread).
// Frames travel in pooled jobs whose buffers are reused; bounded queues join the stages
// and the ordered ones restore frame order behind parallel matchers. This file sets the
// pipeline up, starts and ends a run and writes its summary; pipeline_stages.cpp holds
// what each stage thread does.
#include "pipeline/pipeline.hpp"
#include "pipeline/pipeline_run.hpp"

#include "calibration/geometry_check.hpp"
#include "files/atomic_file.hpp"
#include "core/error.hpp"
#include "core/image_io.hpp"
#include "core/json.hpp"
#include "core/progress.hpp"
#include "pipeline/frame_writer.hpp"
#include "pipeline/plugin_instances.hpp"
#include "pipeline/run_summary.hpp"
#include "pipeline/source_grab.hpp"
#include "pipeline/stage_queue.hpp"
#include "pipeline/stage_times.hpp"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sys/resource.h>
#include <unistd.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>
#include <thread>
#include <yaml-cpp/yaml.h>

namespace fs = std::filesystem;

namespace binocle {

// ---- LatestFrame -------------------------------------------------------------------------------

void LatestFrame::onFrame(const FrameResult &r) {
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || slot_) {
        ++skipped_;
        return;
    }
    FrameSnapshot s;
    s.index = r.index;
    s.sequence = r.sequence;
    r.rectified_left.copyTo(s.rectified_left);
    r.disparity.copyTo(s.disparity);
    s.cloud = r.cloud;
    s.metrics = r.metrics;
    slot_ = std::move(s);
}

std::optional<FrameSnapshot> LatestFrame::take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::optional<FrameSnapshot> s = std::move(slot_);
    slot_.reset();
    return s;
}

// ---- Pipeline ----------------------------------------------------------------------------------

namespace {

// For display only: a matcher that cannot say its range still runs (its failures are
// the run's to report), the range is then {0, 0}.
std::pair<int32_t, int32_t> askDisparityRange(Matcher &m) {
    try {
        return m.disparityRange();
    } catch (const std::exception &e) {
        spdlog::debug("matcher disparity range: {}", e.what());
        return {0, 0};
    }
}

} // namespace

Pipeline::Pipeline(const RigConfig &rig, const PluginHost &) : rig_(rig), instances_(std::make_unique<PluginInstances>()) {
    // In the order they go back in reverse: the source last.
    auto &sources = instances_->edit<Source>();
    auto &matchers = instances_->edit<Matcher>();
    auto &transforms = instances_->edit<CloudTransform>();
    auto &evaluators = instances_->edit<EvaluatorSlot>();
    sources.push_back(std::make_unique<Source>(*rig.source().record, rig.source().params, rig.source().isolation));
    for (int i = 0; i < rig.runtime.matcher_instances; ++i)
        matchers.push_back(std::make_unique<Matcher>(*rig.matcher().record, rig.matcher().params, rig.matcher().isolation));
    for (const auto &t : rig.transforms()) transforms.push_back(std::make_unique<CloudTransform>(*t.record, t.params, t.isolation));
    for (const auto &e : rig.evaluators()) evaluators.push_back(makeEvaluator(e));
    disparityRange_ = askDisparityRange(*matchers.front());
}

Source &Pipeline::source() {
    return *instances_->of<Source>().front();
}

std::string Pipeline::sourceStatistics() const {
    std::lock_guard<std::mutex> lock(statisticsMutex_);
    return sourceStatistics_;
}

void Pipeline::refreshSourceStatistics() {
    std::string stats = source().statistics();
    std::lock_guard<std::mutex> lock(statisticsMutex_);
    sourceStatistics_ = std::move(stats);
}

std::unique_ptr<Pipeline::EvaluatorSlot> Pipeline::makeEvaluator(const PluginBlock &e) {
    auto slot = std::make_unique<EvaluatorSlot>();
    slot->name = e.plugin;
    EvaluatorSlot *raw = slot.get();
    HostSink sink;
    sink.metric = [raw](const std::string &name, double value, const std::string &unit) {
        if (raw->flat) raw->flat->emplace_back(raw->name + "." + name, value);
        if (!raw->target) return;
        (*raw->target)[name] = value;
        if (!unit.empty()) (*raw->target)[name + "_unit"] = unit;
    };
    sink.text = [raw](const std::string &name, const std::string &text) {
        if (raw->target) (*raw->target)[name] = text;
    };
    slot->evaluator = std::make_unique<Evaluator>(*e.record, e.params, sink, e.isolation);
    return slot;
}

namespace {

// Same plugin with the same settings: the instance can stay.
bool sameBlock(const PluginBlock &a, const PluginBlock &b) {
    if (a.plugin != b.plugin || a.params.size() != b.params.size()) return false;
    for (int32_t i = 0; i < a.params.size(); ++i) {
        const binocle_param &x = a.params.data()[i], &y = b.params.data()[i];
        if (std::string(x.name) != y.name || x.type != y.type || x.i != y.i || x.explicit_ != y.explicit_) return false;
        if (!(x.d == y.d || (std::isnan(x.d) && std::isnan(y.d)))) return false;
        if ((x.s == nullptr) != (y.s == nullptr) || (x.s && std::string(x.s) != y.s)) return false;
    }
    return true;
}

} // namespace

void Pipeline::reconfigure(const RigConfig &rig) {
    // Everything new is created first: a refusal throws before anything is replaced.
    std::unique_ptr<Source> nextSource;
    std::vector<std::unique_ptr<Matcher>> nextMatchers;
    std::vector<std::unique_ptr<CloudTransform>> nextTransforms(rig.transforms().size());
    std::vector<std::unique_ptr<EvaluatorSlot>> nextEvaluators(rig.evaluators().size());
    const bool newSource = !sameBlock(rig.source(), rig_.source()) || rig.calibration_file != rig_.calibration_file;
    if (newSource) nextSource = std::make_unique<Source>(*rig.source().record, rig.source().params, rig.source().isolation);
    // As many instances as the stage has threads (runtime.matcher_instances is read when
    // the pipeline is made).
    const size_t matcherThreads = instances_->of<Matcher>().size();
    if (!sameBlock(rig.matcher(), rig_.matcher()))
        for (size_t i = 0; i < matcherThreads; ++i)
            nextMatchers.push_back(std::make_unique<Matcher>(*rig.matcher().record, rig.matcher().params, rig.matcher().isolation));
    const std::pair<int32_t, int32_t> range = nextMatchers.empty() ? disparityRange_ : askDisparityRange(*nextMatchers.front());
    for (size_t i = 0; i < rig.transforms().size(); ++i)
        if (i >= rig_.transforms().size() || !sameBlock(rig.transforms()[i], rig_.transforms()[i]))
            nextTransforms[i] = std::make_unique<CloudTransform>(*rig.transforms()[i].record, rig.transforms()[i].params,
                                                                   rig.transforms()[i].isolation);
    for (size_t i = 0; i < rig.evaluators().size(); ++i)
        if (i >= rig_.evaluators().size() || !sameBlock(rig.evaluators()[i], rig_.evaluators()[i]))
            nextEvaluators[i] = makeEvaluator(rig.evaluators()[i]);
    if (nextSource && sourceStarted_) {
        // A camera is held by one instance at a time: the old one lets go first, and
        // takes the device back when the new one cannot start.
        source().stop();
        try {
            nextSource->start();
        } catch (...) {
            source().start();
            throw;
        }
    }
    if (nextSource) {
        instances_->edit<Source>().front() = std::move(nextSource);
        calibrationReady_ = false; // another source may publish another calibration
    }
    if (!nextMatchers.empty()) instances_->edit<Matcher>() = std::move(nextMatchers);
    disparityRange_ = range;
    auto &transforms = instances_->edit<CloudTransform>();
    for (size_t i = 0; i < nextTransforms.size(); ++i)
        if (!nextTransforms[i]) nextTransforms[i] = std::move(transforms[i]);
    transforms = std::move(nextTransforms);
    auto &evaluators = instances_->edit<EvaluatorSlot>();
    for (size_t i = 0; i < nextEvaluators.size(); ++i)
        if (!nextEvaluators[i]) nextEvaluators[i] = std::move(evaluators[i]);
    evaluators = std::move(nextEvaluators);
    const int instances = rig_.runtime.matcher_instances;
    rig_ = rig;
    rig_.runtime.matcher_instances = instances;
}

Pipeline::~Pipeline() = default;

void Pipeline::prepareCalibration(const cv::Size &imageSize) {
    if (rig_.calibration_file) {
        calibration_ = StereoCalibration::load(*rig_.calibration_file);
        calibrationYaml_ = readTextFile(*rig_.calibration_file);
    } else {
        calibrationYaml_ = source().calibration();
        if (calibrationYaml_.empty())
            throw Error(rig_.file + ": no calibration: the rig names no 'calibration:' file and source plugin '" +
                        rig_.source().plugin + "' publishes none (run `binocle calibrate`, or add calibration: FILE)");
        calibration_ = StereoCalibration::fromYaml(calibrationYaml_, "calibration published by source '" + rig_.source().plugin + "'");
    }
    // Geometry check before the first frame: a calibration made for another image size,
    // with the cameras swapped or for another baseline gives a collapsed cloud or
    // negative disparities.
    GeometryExpectation expected;
    expected.image_size = imageSize;
    expected.baseline_mm = statedGeometry(rig_.source()).baseline_mm;
    expected.source = rig_.source().plugin;
    checkGeometry(calibration_, expected,
                  rig_.calibration_file ? "calibration " + *rig_.calibration_file
                                        : "the calibration published by source '" + rig_.source().plugin + "'");
    if (!calibration_.rectified) {
        cv::initUndistortRectifyMap(calibration_.M1, calibration_.D1, calibration_.R1, calibration_.P1, imageSize, CV_32FC1,
                                    map1x_, map1y_);
        cv::initUndistortRectifyMap(calibration_.M2, calibration_.D2, calibration_.R2, calibration_.P2, imageSize, CV_32FC1,
                                    map2x_, map2y_);
    }
    projector_ = CloudProjector(calibration_, rig_.outputs.max_range_mm);
    imageSize_ = imageSize;
    calibrationReady_ = true;
}

// The maps, the projector and the geometry check were made for the first frame's size:
// a frame of another size would be rectified and triangulated with the wrong geometry.
void Pipeline::checkFrameSize(const LentFrame &frame, int64_t ordinal) const {
    const cv::Size left = frame.left().size(), right = frame.right().size();
    if (left == imageSize_ && right == imageSize_) return;
    throw Error("frame " + std::to_string(ordinal) + " (sequence " + std::to_string(frame.raw().sequence) + ") of source '" +
                rig_.source().plugin + "': left image " + sizeText(left) + ", right image " + sizeText(right) + "; expected " +
                sizeText(imageSize_) + " as the frames before it and the calibration (" +
                (rig_.calibration_file ? *rig_.calibration_file : "published by the source") +
                "): refusing to process it with the wrong geometry (did the source change its image size mid-run?)");
}

// Up to runtime.queue_depth frames wait at the source: when frames of this size cannot all
// fit in memory, the run would die in whatever allocation comes first (an image decode, a
// copy), far from its cause. Refused at the first frame, naming the key and what fits.
void Pipeline::checkQueueMemory(const LentFrame &frame) const {
    const auto bytesOf = [](const cv::Mat &m) { return static_cast<double>(m.total() * m.elemSize()); };
    const double pair = bytesOf(frame.left()) + bytesOf(frame.right());
    const int depth = rig_.runtime.queue_depth;
    double memory = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGESIZE));
    for (const int limit : {RLIMIT_AS, RLIMIT_DATA})
        if (struct rlimit r {}; ::getrlimit(limit, &r) == 0 && r.rlim_cur != RLIM_INFINITY)
            memory = std::min(memory, static_cast<double>(r.rlim_cur));
    // Half of it: the stages, the plugins and the outputs need the rest.
    if (!(memory > 0) || pair * depth <= memory / 2) return;
    auto mb = [](double b) { return std::to_string(static_cast<int64_t>(std::ceil(b / (1 << 20)))); };
    const auto fits = static_cast<int64_t>(std::floor(memory / 2 / pair));
    throw Error("runtime.queue_depth " + std::to_string(depth) + ": up to " + std::to_string(depth) + " frames of " +
                sizeText(frame.left().size()) + " (" + mb(pair) + " MB a pair) may wait at the source, " + mb(pair * depth) +
                " MB in all; this process may use " + mb(memory) + " MB (memory, or ulimit -v): expected a queue_depth of at most " +
                std::to_string(std::max<int64_t>(1, fits)) + " for frames this large");
}

Json Pipeline::run(const RunOptions &options, const std::function<void(const FrameResult &)> &onFrame) {
    outDir_ = options.out_dir;
    if (!outDir_.empty()) {
        std::error_code ec;
        fs::create_directories(outDir_, ec);
        if (ec) throw Error("--out " + outDir_ + ": cannot create the folder: " + ec.message());
    }
    const RuntimeOptions &rt = rig_.runtime;
    // Between processing stages a few frames are enough to absorb jitter; the policy
    // acts on the queue at the source, which is the rig's queue_depth.
    const size_t stageDepth = static_cast<size_t>(std::max(2, rt.matcher_instances));
    RunState s(options, static_cast<size_t>(rt.queue_depth), stageDepth);
    const bool live = sourceIsLive(source());
    s.policy = rt.policy ? *rt.policy : live ? RuntimeOptions::Policy::Latest : RuntimeOptions::Policy::Lossless;
    const size_t matcherThreads = instances_->of<Matcher>().size();
    const size_t jobs = matcherThreads + 3 * stageDepth + 3;
    for (size_t i = 0; i < jobs; ++i) s.pool.push_back(std::make_unique<Job>());
    s.matched.setProducers(static_cast<int>(matcherThreads));
    Json summary = runHeader(rig_, s.policy, live);

    const auto start = Clock::now();
    try {
        if (!outDir_.empty()) s.writers.push_back((s.folder = makeFolderWriter(outDir_, rig_.outputs)).get());
        for (FrameWriter *w : options.writers) s.writers.push_back(w);
    } catch (const std::exception &e) {
        s.fail(e.what());
    }
    if (!s.aborted) {
        std::vector<std::thread> threads;
        threads.emplace_back([&] { acquire(s); });
        for (size_t i = 0; i < matcherThreads; ++i) threads.emplace_back([&, i] { rectifyAndMatch(s, i); });
        threads.emplace_back([&] { cloudAndTransforms(s); });
        threads.emplace_back([&] { evaluate(s); });
        write(s, onFrame);
        for (auto &t : threads) t.join();
    }
    const std::string failure = finishSummary(s, summary, secondsSince(start));
    if (!outDir_.empty()) writeFileAtomic((fs::path(outDir_) / "summary.json").string(), dumpJson(summary));
    if (!failure.empty()) throw Error(failure);
    return summary;
}

// The figures of a finished run: the evaluators' totals, counts, status, drops, stage
// times, isolation and calibration. Returns the run's failure ("" when none).
std::string Pipeline::finishSummary(RunState &s, Json &summary, double elapsed) {
    const bool interrupted = s.stopRequested() && !s.endOfStream;
    std::string failure = s.failure;
    if (failure.empty()) {
        try {
            Json totals = Json::object();
            for (const auto &slot : instances_->of<EvaluatorSlot>()) {
                Json figures = Json::object();
                slot->target = &figures;
                slot->evaluator->finish();
                slot->target = nullptr;
                totals[slot->name] = std::move(figures);
            }
            summary["metrics"] = totals;
        } catch (const std::exception &e) {
            failure = e.what();
        }
    }
    std::string stats;
    try {
        stats = source().statistics();
    } catch (const std::exception &e) {
        spdlog::warn("source statistics: {}", e.what());
    }
    summary["frame_count"] = s.written;
    summary["frames_grabbed"] = s.grabbed;
    summary["seconds"] = elapsed;
    summary["frames_per_second"] = elapsed > 0 ? s.written / elapsed : 0.0;
    summary["status"] = !failure.empty() ? "failed" : interrupted ? "interrupted" : "ok";
    if (!failure.empty()) summary["error"] = failure;
    for (FrameWriter *w : s.writers) {
        try {
            w->finish(summary);
        } catch (const std::exception &e) {
            if (failure.empty()) summary["error"] = failure = e.what();
            summary["status"] = "failed";
        }
    }
    // Where the time of a frame goes (only frames that went all the way through).
    summary["stage_seconds_per_frame"] = s.times.summary();
    if (!stats.empty()) summary["source_statistics"] = stats;
    summary["dropped"] = droppedSummary(s.droppedByPolicy, stats);
    const RuntimeOptions &rt = rig_.runtime;
    if (s.sourceErrors > 0 || rt.on_source_error == RuntimeOptions::OnSourceError::Retry)
        summary["source_errors"] = {{"outages", s.sourceErrors}, {"recovered", s.recoveries}, {"last", s.lastSourceError}};
    // Plugins in helper processes (`isolation: process`): restarts, and the calls whose
    // result they cost (a source's grabs, frames without disparity, dropped clouds, frames
    // without an evaluator's figures).
    Json isolation = Json::object();
    auto isolated = [&](const std::string &where, const PluginInstanceBase &p) {
        if (!p.isolated()) return;
        Json &e = isolation[where];
        e["plugin"] = p.record().name;
        e["restarts"] = e.value("restarts", 0) + p.restarts();
        e["lost_calls"] = e.value("lost_calls", int64_t{0}) + p.lostCalls();
    };
    isolated("source", source());
    for (const auto &m : instances_->of<Matcher>()) isolated("matcher", *m);
    const auto &transforms = instances_->of<CloudTransform>();
    for (size_t i = 0; i < transforms.size(); ++i) isolated("transforms[" + std::to_string(i) + "]", *transforms[i]);
    const auto &evaluators = instances_->of<EvaluatorSlot>();
    for (size_t i = 0; i < evaluators.size(); ++i) isolated("evaluators[" + std::to_string(i) + "]", *evaluators[i]->evaluator);
    if (!isolation.empty()) summary["isolation"] = isolation;
    if (calibrationReady_) {
        summary["calibration"] = {{"baseline_mm", calibration_.baselineMm()},
                                  {"focal_length_px", calibration_.focalLengthPx()},
                                  {"image_width", calibration_.image_size.width},
                                  {"image_height", calibration_.image_size.height}};
    }
    return failure;
}

} // namespace binocle
