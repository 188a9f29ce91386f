// SPDX-License-Identifier: MIT
// Experiments as YAML (METHOD.md E1, E2): a base rig plus a list of tests, each setting
// baseline, focal length, range, camera height or inclination. Everything is validated
// before the first test runs; then each test runs the rig's pipeline and a row of
// results is kept; at the end come results.csv/json and charts.
#pragma once

#include "core/json.hpp"
#include "experiment/board_calibration.hpp"
#include "host/plugin_host.hpp"
#include "method/design.hpp"

#include <atomic>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>
#include <yaml-cpp/yaml.h>

namespace binocle {

// The variables of METHOD.md a test may set, with the YAML key of each.
struct TestGeometry {
    double baseline_mm = 0;     // B
    double focal_length_mm = 0; // f
    double range_mm = 0;        // R
    double camera_height_mm = 0;
    double inclination_deg = 0;
};

struct ExperimentTest {
    std::string id;                          // "1", "2" ... as written
    TestGeometry geometry;
    std::vector<std::pair<std::string, std::string>> set; // extra overrides: rig path -> YAML value
    int repeats = 0;                         // > 0: overrides the experiment's
    // What the paper reported for this test (`paper:` block): figure -> value, shown
    // beside the measured one.
    std::vector<std::pair<std::string, double>> paper;
    int line = 0;                            // where the test stands in the file
};

// One lens of the lens table: its focal length and the rig overrides that model it
// (e.g. the simulated head's distortion: short lenses distort more).
struct Lens {
    double focal_length_mm = 0;
    std::vector<std::pair<std::string, std::string>> set; // rig path -> YAML value
};

struct ChartSpec {
    std::string type;                // "bars" or "scatter"
    std::string metric;              // bars: the value; scatter: y
    std::string x = "form_factor";   // scatter: x
    std::string title;
    std::string file;                // output stem, without extension
    std::vector<double> reference_lines;
};

struct Experiment {
    std::string file;     // absolute path of the experiment YAML
    std::string name, description;
    std::string rig_file; // the base rig
    YAML::Node rig;       // the base rig's tree
    // The base rig's text and the rig_set: paths and values laid over it: each test's rig
    // is parsed anew from them, so that its nodes keep their lines (YAML::Clone would
    // put every one at line 1, column 1).
    std::string rig_text;
    std::vector<std::pair<std::string, std::string>> rig_set;
    int64_t frames = 1;
    // `dataset:` (the benchmarks): a test per scene folder of the dataset, named after it,
    // no geometry; a row of the means after the scenes (dataset_tests.hpp).
    bool dataset_tests = false;
    std::vector<double> lenses_mm;            // the focal lengths the rig has
    double baseline_min_mm = 0, baseline_max_mm = 0;
    // The head's sensor and matcher (method::StereoDesign, the one head description):
    // pixel pitch (0: unknown, no sensor-aware columns), image size, the matcher's search
    // (disparity_search_px, for the minimum range). Each test configures its B, f, hc, θ.
    method::StereoDesign head;
    std::vector<std::string> overrides;       // --set texts applied to the file
    std::map<std::string, std::vector<std::string>> bind; // variable -> rig paths
    std::vector<ExperimentTest> tests;
    std::vector<ChartSpec> charts;

    // Repeats: each renders with its own noise seed, written to `seed_path` of the rig;
    // seeds[r] when the list is given, else seed + r. jitter: rig path -> half width of
    // a uniform perturbation of that path's value, drawn per repeat from its seed
    // (e.g. the panel's placement and the camera's true height; the paths the rig is
    // told stay nominal).
    int repeats = 1;
    uint32_t seed = 1;
    std::vector<uint32_t> seeds;
    std::string seed_path = "source.seed";
    std::vector<std::pair<std::string, double>> jitter;

    // "exact": the source's own calibration; "board": calibrated per test from board
    // pairs the source renders (board_calibration).
    std::string calibration = "exact";
    BoardCalibrationSpec board_calibration;

    std::string lens_table_file;   // absolute; empty: none
    std::vector<Lens> lens_table;

    // The test panel, for the predictors that need it (sensor-aware η3D).
    method::PanelPlacement panel;

    int repeatsOf(const ExperimentTest &t) const { return t.repeats > 0 ? t.repeats : repeats; }
    uint32_t seedOf(int repeat) const;
};

// Reads and validates an experiment, including every test's resulting rig against the
// plugins `host` found. Throws binocle::Error with file, line and reason; nothing runs.
// `overrides` (`--set repeats=10`, `--set calibration=board`) apply to the experiment
// file's tree before it is read, like a rig's --set.
Experiment loadExperiment(const std::string &file, const PluginHost &host, const std::vector<std::string> &overrides = {});

// An experiment made in code: the base rig file and one test per geometry (ids 1, 2 ...),
// bound to the rig the same way as a file without `bind:`. Validated like a file.
Experiment makeExperiment(const std::string &name, const std::string &rig_file, const std::vector<TestGeometry> &tests,
                          const PluginHost &host);

// The rig of one test: the base rig with the test's lens (lens table), variables and
// overrides applied; repeat >= 0 adds that repeat's seed and jitter when the
// experiment repeats (repeats > 1 or a seed list).
YAML::Node rigForTest(const Experiment &e, const ExperimentTest &t, int repeat = -1);

struct ExperimentOptions {
    std::string out_dir;
    bool progress = true;
    std::vector<std::string> only; // test ids to run; empty = all
    int shard_index = 1, shard_count = 1; // --shard K/N: the tests whose position p (0-based, file order) has p % N == K - 1
    // --force: replace another experiment's results in out_dir (this experiment's own are
    // replaced by a run of every test anyway; a partial run never replaces a table).
    bool replace = false;
    // Polled before each test: once true, no further test starts and the tables keep the
    // status "interrupted" (the Python module's Ctrl-C). Null: every test runs.
    const std::atomic<bool> *stop = nullptr;
};

// One row of results.csv / results.json: a test's variables and every figure measured.
struct ExperimentRow {
    std::string test_id;
    TestGeometry geometry;
    std::string status = "ok"; // or "failed", with `error`
    std::string error;
    std::vector<std::pair<std::string, double>> values; // column -> value, in column order (NaN: none)

    // NaN when the column is absent.
    double get(const std::string &column) const;
    void put(const std::string &column, double value);
};

struct ExperimentResult {
    std::vector<ExperimentRow> rows; // one per test run, in order
    int64_t failed = 0;
    double seconds = 0;
    bool interrupted = false; // ExperimentOptions::stop ended it before its last test
};

// "K/N" -> (K, N), 1 <= K <= N; throws binocle::Error naming the option and the value.
std::pair<int, int> parseShard(const std::string &text);

// The tests a run does: its shard's, and of those the ones `options.only` names. Throws
// binocle::Error naming an id the experiment lacks, or when none is selected.
std::vector<const ExperimentTest *> selectTests(const Experiment &e, const ExperimentOptions &options);

// Joins the results.json of shards (or partial runs) of one experiment in `dirs` into
// `out_dir`: the rows in the experiment's test order, the predictors' rho and the charts
// recomputed over all of them, each test's folder copied. Throws when two folders hold
// the same test, when they come from different experiments, when the experiment or its
// rig changed since a folder was written, or when `out_dir` (not one of `dirs`) holds
// results and `replace` is false. A set that lacks tests is merged with status
// "partial" and its `missing_tests` listed (a warning says which).
ExperimentResult mergeExperimentResults(const std::string &out_dir, const std::vector<std::string> &dirs, const PluginHost &host,
                                        bool replace = false);

// Runs every test and writes results.csv, results.json, charts and per-test outputs
// into out_dir/test_<id>/. Returns the rows it wrote. A test whose pipeline fails is
// recorded with its error and the others still run; the caller decides the exit status
// from `failed`. results.json's `status` is "interrupted" until the last test is done,
// then "complete" (every test) or "partial" (--tests, --shard). Refuses unknown --tests
// ids, and results already in out_dir that this run must not replace (ExperimentOptions).
ExperimentResult runExperiment(const Experiment &e, const PluginHost &host, const ExperimentOptions &options);

} // namespace binocle
