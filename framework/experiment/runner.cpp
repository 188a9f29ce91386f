// SPDX-License-Identifier: MIT
// Running an experiment: each selected test's repeats through the rig's pipeline, a row
// per test, the tables rewritten after every test and the charts at the end.
#include "experiment/dataset_tests.hpp"
#include "experiment/experiment.hpp"
#include "experiment/results.hpp"
#include "experiment/test_rig.hpp"

#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "core/progress.hpp"
#include "input/integer_range.hpp"
#include "method/design.hpp"
#include "method/predictors.hpp"
#include "method/statistics.hpp"
#include "pipeline/pipeline.hpp"

#include <binocle/text.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>

#include <spdlog/spdlog.h>

namespace fs = std::filesystem;

namespace binocle {

using namespace experiment;

namespace {

std::string testLabel(const ExperimentTest &t) {
    std::ostringstream os;
    os << "test " << t.id << " (R " << t.geometry.range_mm / 1000 << " m, B " << t.geometry.baseline_mm << " mm, f "
       << t.geometry.focal_length_mm << " mm";
    if (t.geometry.inclination_deg != 0) os << ", θ " << t.geometry.inclination_deg << "°";
    return os.str() + ")";
}

// The columns every row starts with: the test's variables and the design figures.
void putDesign(Row &row, const Experiment &e, const ExperimentTest &t) {
    const auto &g = t.geometry;
    row.put("baseline_mm", g.baseline_mm);
    row.put("focal_length_mm", g.focal_length_mm);
    row.put("range_mm", g.range_mm);
    row.put("camera_height_mm", g.camera_height_mm);
    row.put("inclination_deg", g.inclination_deg);
    row.put("form_factor", method::formFactor(g.baseline_mm, g.focal_length_mm, g.range_mm)); // Eq. 7
    if (e.head.pixel_pitch_um > 0) {
        const method::StereoDesign d = e.head.configured(g.baseline_mm, g.focal_length_mm, g.camera_height_mm, g.inclination_deg);
        const method::DesignFigures f = method::designFigures(d, g.range_mm, method::kMatchingErrorPx, &e.panel);
        row.put("expected_disparity_px", f.disparity_px);
        row.put("depth_resolution_mm", f.depth_resolution_mm);
        row.put("stereo_field_width_mm", f.stereo_field_width_mm);
        const method::PredictorValues p = method::predictors(d, g.range_mm, e.panel);
        row.put("predictor.ff_band", p.ff_band);
        row.put("predictor.depth_resolution", p.depth_resolution);
        row.put("predictor.sensor_aware", p.sensor_aware);
    } else {
        row.put("predictor.ff_band", -method::formFactorBandDistance(method::formFactor(g.baseline_mm, g.focal_length_mm, g.range_mm)));
    }
}

// One repeat of a test: the pipeline over the experiment's frames; figures averaged over
// the frames ("<evaluator>.<metric>" and the bare main metrics) and the valid-pixel ratio.
std::vector<std::pair<std::string, double>> runRepeat(const Experiment &e, const YAML::Node &rigNode, const PluginHost &host,
                                                      const std::string &outDir) {
    RigConfig rig = rigFromNode(rigNode, e.rig_file, host);
    Pipeline pipeline(rig, host);
    RunOptions run;
    run.max_frames = e.frames;
    run.out_dir = outDir;
    run.progress = false;
    std::vector<std::pair<std::string, double>> sums;
    std::vector<int> counts;
    double valid = 0;
    int frames = 0;
    pipeline.run(run, [&](const FrameResult &fr) {
        ++frames;
        valid += fr.valid_pixel_ratio;
        for (const auto &figure : fr.figures) {
            const std::string &name = figure.first; // a structured binding cannot be captured in C++17 (clang)
            const double value = figure.second;
            auto it = std::find_if(sums.begin(), sums.end(), [&](const auto &p) { return p.first == name; });
            if (it == sums.end()) {
                sums.emplace_back(name, 0.0);
                counts.push_back(0);
                it = sums.end() - 1;
            }
            if (std::isfinite(value)) {
                it->second += value;
                ++counts[it - sums.begin()];
            }
        }
    });
    std::vector<std::pair<std::string, double>> out;
    auto put = [&](const std::string &k, double v) {
        for (auto &[n, x] : out)
            if (n == k) return;
        out.emplace_back(k, v);
    };
    if (!e.dataset_tests)
        for (const auto &k : kMainMetrics) put(k, NAN);
    out.emplace_back("valid_pixel_ratio", frames ? valid / frames : NAN);
    for (size_t k = 0; k < sums.size(); ++k) {
        const double mean = counts[k] ? sums[k].second / counts[k] : NAN;
        const std::string &name = sums[k].first; // "<evaluator>.<metric>"
        const std::string metric = name.substr(name.find('.') + 1);
        if (std::find(kMainMetrics.begin(), kMainMetrics.end(), metric) != kMainMetrics.end())
            for (auto &[n, x] : out)
                if (n == metric && !std::isfinite(x)) x = mean;
        out.emplace_back(name, mean);
    }
    return out;
}

Row runTest(const Experiment &e, const ExperimentTest &t, const PluginHost &host, const std::string &outDir) {
    Row row;
    row.test = &t;
    if (!e.dataset_tests) { // a dataset's scene has no geometry
        putDesign(row, e, t);
        for (const auto &k : kMainMetrics) row.put(k, NAN);
    }
    row.put("valid_pixel_ratio", NAN);
    const int repeats = e.repeatsOf(t);
    const bool repeating = repeats > 1 || !e.seeds.empty();
    if (repeating)
        for (const auto &k : kRepeatedMetrics)
            for (const char *suffix : {"_sd", "_ci95_low", "_ci95_high"}) row.put(k + suffix, NAN);
    row.put("repeats", repeats);
    const std::string testDir = (fs::path(outDir) / ("test_" + t.id)).string();
    try {
        std::string calibrationFile;
        if (e.calibration == "board") {
            const std::string name = "calibration/calib_B" + num(std::round(t.geometry.baseline_mm)) + "_f" +
                                     num(std::round(t.geometry.focal_length_mm * 10) / 10) + ".yml";
            calibrationFile = (fs::path(testDir) / name).string();
            const double pitch = e.head.pixel_pitch_um;
            BoardCalibrationOutcome c =
                calibrateConfiguration(rigForTest(e, t), e.rig_file, e.board_calibration, host, calibrationFile, pitch);
            row.put("calibration_rms_px", c.rms_px);
            row.put("calibration_baseline_error_percent", c.baseline_error_percent);
            row.put("calibration_focal_length_error_percent", c.focal_length_error_percent);
            row.put("calibration_pairs_used", c.pairs_used);
            c.file = "test_" + t.id + "/" + name; // relative: identical whichever folder the run wrote to
            row.details["calibration"] = c.toJson();
        }
        // Per repeat: every figure; the outputs (disparity, cloud, views) of the first only.
        std::vector<std::vector<std::pair<std::string, double>>> results;
        OJson perRepeat = OJson::array();
        for (int k = 0; k < repeats; ++k) {
            YAML::Node rig = rigForTest(e, t, k);
            if (!calibrationFile.empty()) rig["calibration"] = calibrationFile;
            std::string repeatDir = testDir;
            if (k > 0) { // later repeats: their summary and evaluator views, no images or clouds
                repeatDir = (fs::path(testDir) / ("repeat_" + std::to_string(k))).string();
                for (const char *o : {"disparity_png", "disparity_color", "disparity_pfm", "cloud_ply", "rectified_png"})
                    rig["outputs"][o] = false;
            }
            results.push_back(runRepeat(e, rig, host, repeatDir));
            if (repeating) {
                OJson one = OJson::object();
                one["seed"] = e.seedOf(k);
                if (!e.jitter.empty()) {
                    OJson j = OJson::object();
                    for (const auto &[path, w] : e.jitter) {
                        const YAML::Node n = nodeAt(rig, path);
                        j[path] = n.IsScalar() ? OJson(n.as<double>()) : OJson();
                    }
                    one["jitter"] = j;
                }
                for (const auto &[n, v] : results.back())
                    if (std::find(kRepeatedMetrics.begin(), kRepeatedMetrics.end(), n) != kRepeatedMetrics.end())
                        one[n] = std::isfinite(v) ? OJson(v) : OJson();
                perRepeat.push_back(one);
            }
        }
        // Means over the repeats, in the order the first repeat reported them.
        for (const auto &[name, unused] : results.front()) {
            (void)unused;
            std::vector<double> samples;
            for (const auto &r : results)
                for (const auto &[n, v] : r)
                    if (n == name) samples.push_back(v);
            const method::Summary s = method::summarize(samples);
            row.put(name, s.n ? s.mean : NAN);
            if (repeating && std::find(kRepeatedMetrics.begin(), kRepeatedMetrics.end(), name) != kRepeatedMetrics.end()) {
                row.put(name + "_sd", s.n ? s.sd : NAN);
                row.put(name + "_ci95_low", s.ci95_low);
                row.put(name + "_ci95_high", s.ci95_high);
            }
        }
        if (repeating) row.details["per_repeat"] = perRepeat;
    } catch (const std::exception &x) {
        row.status = "failed";
        row.error = x.what();
        spdlog::error("experiment: {} failed: {}", testLabel(t), x.what());
    }
    if (!t.paper.empty()) {
        OJson paper = OJson::object();
        for (const auto &[k, reported] : t.paper) {
            const double measured = row.get(k);
            row.put("paper_reported." + k, reported); // not "paper.": the paper evaluator's figures are named so
            paper[k] = {{"reported", reported},
                        {"measured", std::isfinite(measured) ? OJson(measured) : OJson()},
                        {"difference", std::isfinite(measured) ? OJson(measured - reported) : OJson()}};
        }
        row.details["paper_reported"] = paper;
    }
    return row;
}

} // namespace

std::pair<int, int> parseShard(const std::string &text) {
    const auto slash = text.find('/');
    int64_t k = 0, n = 0;
    std::string why;
    if (slash == std::string::npos || !input::parseInteger(text.substr(0, slash), k, &why, 1, 1000000) ||
        !input::parseInteger(text.substr(slash + 1), n, &why, 1, 1000000))
        throw Error("--shard " + sdk::printable(text) + ": expected K/N, e.g. --shard 2/8 (the second of eight shares)" +
                    (why.empty() ? "" : "; " + why));
    if (k > n) throw Error("--shard " + sdk::printable(text) + ": expected 1 <= K <= N");
    return {static_cast<int>(k), static_cast<int>(n)};
}

// The tests this run does: its shard's, and of those the ones --tests names. An id that
// is not in the experiment is an error (a typo would otherwise skip silently).
std::vector<const ExperimentTest *> selectTests(const Experiment &e, const ExperimentOptions &options) {
    for (const auto &id : options.only)
        if (std::none_of(e.tests.begin(), e.tests.end(), [&](const ExperimentTest &t) { return t.id == id; })) {
            std::vector<std::string> ids;
            for (const auto &t : e.tests) ids.push_back(t.id);
            throw Error("--tests " + join(options.only) + ": experiment " + e.file + " has no test '" + sdk::printable(id) +
                        "' (its tests: " + join(ids) + ")");
        }
    std::vector<const ExperimentTest *> selected;
    for (size_t p = 0; p < e.tests.size(); ++p) {
        const auto &t = e.tests[p];
        if (static_cast<int>(p % static_cast<size_t>(options.shard_count)) != options.shard_index - 1) continue;
        if (options.only.empty() || std::find(options.only.begin(), options.only.end(), t.id) != options.only.end())
            selected.push_back(&t);
    }
    if (selected.empty() && (options.shard_count == 1 || !options.only.empty()))
        throw Error("experiment " + e.file + ": no test selected (ids: " + join(options.only) + ")");
    return selected;
}

namespace {

// What --out already holds decides whether this run may write there: nothing of an
// experiment's; this experiment's own results when every test runs again (they are
// cleared first, so an interrupted re-run cannot leave old charts beside a short
// table); another experiment's only with `replace` (--force). A partial run never
// replaces a table.
void prepareOutput(const Experiment &e, const ExperimentOptions &options, size_t selected) {
    std::error_code ec;
    const fs::path existing = fs::path(options.out_dir) / "results.json";
    if (!fs::exists(existing, ec)) return;
    if (selected < e.tests.size())
        throw Error("--out " + options.out_dir + " already holds results (" + existing.string() +
                    "); a partial run (--tests or --shard) would replace that table with " + std::to_string(selected) + " of " +
                    std::to_string(e.tests.size()) +
                    " tests: run into a new folder and join them with `binocle experiment merge OUT DIR...`, "
                    "or run every test");
    const std::string owner = resultsOwner(options.out_dir);
    if (owner != e.file && !options.replace)
        throw Error("--out " + options.out_dir + " already holds the results of " + (owner.empty() ? "another run" : owner) +
                    ", not of " + e.file + ": choose another --out, or --force to replace them");
    clearResults(options.out_dir);
}

} // namespace

ExperimentResult runExperiment(const Experiment &e, const PluginHost &host, const ExperimentOptions &options) {
    if (options.out_dir.empty()) throw Error("experiment: an output folder is needed (--out DIR)");
    if (options.shard_count < 1 || options.shard_index < 1 || options.shard_index > options.shard_count)
        throw Error("experiment: shard " + std::to_string(options.shard_index) + "/" + std::to_string(options.shard_count) +
                    ": expected 1 <= K <= N");
    const std::vector<const ExperimentTest *> selected = selectTests(e, options);
    std::error_code ec;
    fs::create_directories(options.out_dir, ec);
    if (ec) throw Error("--out " + options.out_dir + ": cannot create the folder: " + ec.message());
    prepareOutput(e, options, selected.size());
    TablesMeta meta = metaOf(e, options.shard_index, options.shard_count, host);
    // Until the last test is done the tables say so: a run that dies keeps what it
    // measured, marked as not the whole.
    meta.status = kStatusInterrupted;

    std::vector<Row> rows;
    const ExperimentTest meanTest{"mean", {}, {}, 0, {}, 0}; // dataset: the row of the means
    Progress progress(options.progress, "test", static_cast<int64_t>(selected.size()));
    const auto start = std::chrono::steady_clock::now();
    for (size_t i = 0; i < selected.size(); ++i) {
        if (options.stop && options.stop->load()) {
            // Asked to stop: the tables say "interrupted" and hold the tests done.
            progress.finish();
            writeTables(options.out_dir, e, rows, meta);
            ExperimentResult result = resultOf(rows);
            result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            result.interrupted = true;
            return result;
        }
        const ExperimentTest &t = *selected[i];
        progress.update(static_cast<int64_t>(i), testLabel(t));
        const auto t0 = std::chrono::steady_clock::now();
        Row row = runTest(e, t, host, options.out_dir);
        row.put("seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        rows.push_back(std::move(row));
        // Rewritten after every test: an interrupted experiment keeps what it measured.
        writeTables(options.out_dir, e, rows, meta);
    }
    progress.update(static_cast<int64_t>(selected.size()), "done");
    progress.finish();
    finishRows(options.out_dir, e, rows, meanTest);
    meta.status = selected.size() == e.tests.size() ? kStatusComplete : kStatusPartial;
    writeTables(options.out_dir, e, rows, meta); // last: the status says the charts are there too
    ExperimentResult result = resultOf(rows);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace binocle
