// SPDX-License-Identifier: MIT
// The pipeline: acquire, rectify, match, triangulate, transform, evaluate, write.
#include "pipeline/pipeline.hpp"

#include "calibration/geometry_check.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/image_io.hpp"
#include "core/progress.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace fs = std::filesystem;

namespace binocle {

Pipeline::Pipeline(const RigConfig &rig, const PluginHost &) : rig_(rig) {
    source_ = std::make_unique<Source>(*rig.source.record, rig.source.params);
    matcher_ = std::make_unique<Matcher>(*rig.matcher.record, rig.matcher.params);
    for (const auto &t : rig.transforms) transforms_.push_back(std::make_unique<CloudTransform>(*t.record, t.params));
    for (const auto &e : rig.evaluators) evaluators_.push_back(makeEvaluator(e));
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
    slot->evaluator = std::make_unique<Evaluator>(*e.record, e.params, sink);
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
    std::unique_ptr<Source> source;
    std::unique_ptr<Matcher> matcher;
    std::vector<std::unique_ptr<CloudTransform>> transforms(rig.transforms.size());
    std::vector<std::unique_ptr<EvaluatorSlot>> evaluators(rig.evaluators.size());
    const bool newSource = !sameBlock(rig.source, rig_.source) || rig.calibration_file != rig_.calibration_file;
    if (newSource) source = std::make_unique<Source>(*rig.source.record, rig.source.params);
    if (!sameBlock(rig.matcher, rig_.matcher)) matcher = std::make_unique<Matcher>(*rig.matcher.record, rig.matcher.params);
    for (size_t i = 0; i < rig.transforms.size(); ++i)
        if (i >= rig_.transforms.size() || !sameBlock(rig.transforms[i], rig_.transforms[i]))
            transforms[i] = std::make_unique<CloudTransform>(*rig.transforms[i].record, rig.transforms[i].params);
    for (size_t i = 0; i < rig.evaluators.size(); ++i)
        if (i >= rig_.evaluators.size() || !sameBlock(rig.evaluators[i], rig_.evaluators[i]))
            evaluators[i] = makeEvaluator(rig.evaluators[i]);
    if (source && sourceStarted_) {
        // A camera is held by one instance at a time: the old one lets go first, and
        // takes the device back when the new one cannot start.
        source_->stop();
        try {
            source->start();
        } catch (...) {
            source_->start();
            throw;
        }
    }
    if (source) {
        source_ = std::move(source);
        calibrationReady_ = false; // another source may publish another calibration
    }
    if (matcher) matcher_ = std::move(matcher);
    for (size_t i = 0; i < transforms.size(); ++i)
        if (!transforms[i]) transforms[i] = std::move(transforms_[i]);
    transforms_ = std::move(transforms);
    for (size_t i = 0; i < evaluators.size(); ++i)
        if (!evaluators[i]) evaluators[i] = std::move(evaluators_[i]);
    evaluators_ = std::move(evaluators);
    rig_ = rig;
}

Pipeline::~Pipeline() = default;

void Pipeline::prepareCalibration(const cv::Size &imageSize) {
    if (rig_.calibration_file) {
        calibration_ = StereoCalibration::load(*rig_.calibration_file);
        calibrationYaml_ = readTextFile(*rig_.calibration_file);
    } else {
        calibrationYaml_ = source_->calibration();
        if (calibrationYaml_.empty())
            throw Error(rig_.file + ": no calibration: the rig names no 'calibration:' file and source plugin '" +
                        rig_.source.plugin + "' publishes none (run `binocle calibrate`, or add calibration: FILE)");
        calibration_ = StereoCalibration::fromYaml(calibrationYaml_, "calibration published by source '" + rig_.source.plugin + "'");
    }
    // Geometry check before the first frame: a calibration made for another image size,
    // with the cameras swapped or for another baseline gives a collapsed cloud or
    // negative disparities.
    GeometryExpectation expected;
    expected.image_size = imageSize;
    expected.baseline_mm = statedGeometry(rig_.source).baseline_mm;
    expected.source = rig_.source.plugin;
    checkGeometry(calibration_, expected,
                  rig_.calibration_file ? "calibration " + *rig_.calibration_file
                                        : "the calibration published by source '" + rig_.source.plugin + "'");
    if (!calibration_.rectified) {
        cv::initUndistortRectifyMap(calibration_.M1, calibration_.D1, calibration_.R1, calibration_.P1, imageSize, CV_32FC1,
                                    map1x_, map1y_);
        cv::initUndistortRectifyMap(calibration_.M2, calibration_.D2, calibration_.R2, calibration_.P2, imageSize, CV_32FC1,
                                    map2x_, map2y_);
    }
    calibrationReady_ = true;
}

FrameResult Pipeline::process(const LentFrame &frame) {
    const auto t0 = std::chrono::steady_clock::now();
    FrameResult r;
    auto mark = t0;
    auto stage = [&](const char *name) {
        const auto now = std::chrono::steady_clock::now();
        r.stage_seconds.emplace_back(name, std::chrono::duration<double>(now - mark).count());
        mark = now;
    };
    r.sequence = frame.raw().sequence;
    cv::Mat left = frame.left(), right = frame.right();
    if (!calibrationReady_) prepareCalibration(left.size());
    if (calibration_.rectified) {
        r.rectified_left = left; // zero-copy: the frame stays lent until we return
        r.rectified_right = right;
    } else {
        cv::remap(left, r.rectified_left, map1x_, map1y_, cv::INTER_LINEAR);
        cv::remap(right, r.rectified_right, map2x_, map2y_, cv::INTER_LINEAR);
    }
    stage("rectify");
    r.disparity = matcher_->compute(r.rectified_left, r.rectified_right);
    r.valid_pixel_ratio = static_cast<double>(cv::countNonZero(r.disparity > 0)) / static_cast<double>(r.disparity.total());
    stage("match");
    r.cloud = cloudFromDisparity(r.disparity, calibration_, r.rectified_left, rig_.outputs.max_range_mm);
    stage("cloud");
    for (auto &t : transforms_) {
        binocle_cloud view = r.cloud.view();
        t->apply(view);
        r.cloud.adopt(view);
    }
    stage("transforms");
    r.metrics = Json::object();
    if (!evaluators_.empty()) {
        binocle_image rl{}, rr{}, d{};
        auto wrap = [](const cv::Mat &m, binocle_image &im) {
            im.width = m.cols;
            im.height = m.rows;
            im.stride_bytes = static_cast<int32_t>(m.step[0]);
            im.format = m.type() == CV_32F ? BINOCLE_PIXEL_FLOAT32 : m.channels() == 3 ? BINOCLE_PIXEL_BGR8 : BINOCLE_PIXEL_GRAY8;
            im.data = m.data;
        };
        wrap(r.rectified_left, rl);
        wrap(r.rectified_right, rr);
        wrap(r.disparity, d);
        binocle_cloud cloud = r.cloud.view();
        binocle_eval_input in{};
        in.struct_size = sizeof(in);
        in.frame = &frame.raw();
        in.rectified_left = &rl;
        in.rectified_right = &rr;
        in.disparity = &d;
        in.cloud = &cloud;
        in.calibration_yaml = calibrationYaml_.c_str();
        in.rig_yaml = rig_.resolved_yaml.c_str();
        in.output_dir = outDir_.empty() ? nullptr : outDir_.c_str();
        for (auto &slot : evaluators_) {
            Json figures = Json::object();
            slot->target = &figures;
            slot->flat = &r.figures;
            try {
                slot->evaluator->evaluate(in);
            } catch (...) {
                slot->target = nullptr;
                slot->flat = nullptr;
                throw;
            }
            slot->target = nullptr;
            slot->flat = nullptr;
            r.metrics[slot->name] = std::move(figures);
        }
    }
    stage("evaluators");
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

void writeFrameOutputs(const FrameResult &r, const OutputOptions &o, const std::string &dir) {
    char stem[32];
    std::snprintf(stem, sizeof stem, "%06llu", static_cast<unsigned long long>(r.sequence));
    const fs::path d(dir);
    if (o.disparity_png) writeDisparityPng16((d / ("disparity_" + std::string(stem) + ".png")).string(), r.disparity);
    if (o.disparity_color) writeImage((d / ("disparity_color_" + std::string(stem) + ".png")).string(), colorizeDisparity(r.disparity));
    if (o.disparity_pfm) writePfm((d / ("disparity_" + std::string(stem) + ".pfm")).string(), r.disparity);
    if (o.rectified_png) {
        writeImage((d / ("rectified_left_" + std::string(stem) + ".png")).string(), r.rectified_left);
        writeImage((d / ("rectified_right_" + std::string(stem) + ".png")).string(), r.rectified_right);
    }
    if (o.cloud_ply) writePly((d / ("cloud_" + std::string(stem) + ".ply")).string(), r.cloud);
}


Json Pipeline::run(const RunOptions &options, const std::function<void(const FrameResult &)> &onFrame) {
    outDir_ = options.out_dir;
    if (!outDir_.empty()) {
        std::error_code ec;
        fs::create_directories(outDir_, ec);
        if (ec) throw Error("--out " + outDir_ + ": cannot create the folder: " + ec.message());
    }
    Json summary = {{"rig", rig_.file},
                    {"name", rig_.name},
                    {"source", rig_.source.plugin},
                    {"matcher", rig_.matcher.plugin},
                    {"units", {{"length", "mm"}, {"disparity", "px"}, {"disparity_png_scale", 256}}}};
    Json frames = Json::array();
    const auto start = std::chrono::steady_clock::now();
    int64_t count = 0;
    std::string failure;
    auto writeSummary = [&]() {
        summary["frames"] = frames;
        if (outDir_.empty()) return;
        writeFileAtomic((fs::path(outDir_) / "summary.json").string(), dumpJson(summary));
    };
    try {
        source_->start();
        sourceStarted_ = true;
        Progress progress(options.progress, "frame", options.max_frames);
        while (options.max_frames < 0 || count < options.max_frames) {
            if (options.between_frames && !options.between_frames()) break;
            std::unique_ptr<LentFrame> frame = source_->grab(options.grab_timeout_ms);
            if (!frame) break;
            FrameResult r = process(*frame);
            if (!outDir_.empty()) writeFrameOutputs(r, rig_.outputs, outDir_);
            frames.push_back({{"sequence", r.sequence},
                              {"valid_pixel_ratio", r.valid_pixel_ratio},
                              {"points", r.cloud.size()},
                              {"seconds", r.seconds},
                              {"metrics", r.metrics}});
            if (onFrame) onFrame(r);
            ++count;
            progress.update(count);
        }
        Json totals = Json::object();
        for (auto &slot : evaluators_) {
            Json figures = Json::object();
            slot->target = &figures;
            slot->evaluator->finish();
            slot->target = nullptr;
            totals[slot->name] = std::move(figures);
        }
        summary["metrics"] = totals;
        const std::string stats = source_->statistics();
        if (!stats.empty()) summary["source_statistics"] = stats;
    } catch (const std::exception &e) {
        failure = e.what();
    }
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    summary["frame_count"] = count;
    summary["seconds"] = elapsed;
    summary["status"] = failure.empty() ? "ok" : "failed";
    if (!failure.empty()) summary["error"] = failure;
    if (calibrationReady_) {
        summary["calibration"] = {{"baseline_mm", calibration_.baselineMm()},
                                  {"focal_length_px", calibration_.focalLengthPx()},
                                  {"image_width", calibration_.image_size.width},
                                  {"image_height", calibration_.image_size.height}};
    }
    writeSummary();
    if (!failure.empty()) throw Error(failure);
    return summary;
}

} // namespace binocle
