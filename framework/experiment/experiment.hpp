// SPDX-License-Identifier: MIT
// Experiments as YAML (METHOD.md E1, E2): a base rig plus a list of tests, each setting
// baseline, focal length, range, camera height or inclination. Everything is validated
// before the first test runs; then each test runs the rig's pipeline and a row of
// results is kept; at the end come results.csv/json and charts.
#pragma once

#include "host/plugin_host.hpp"

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
    int line = 0;                            // where the test stands in the file
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
    int64_t frames = 1;
    std::vector<double> lenses_mm;            // the focal lengths the rig has
    double baseline_min_mm = 0, baseline_max_mm = 0;
    double pixel_pitch_um = 0;                // for the sensor-aware figures (0: from the rig)
    int image_width_px = 0;
    std::map<std::string, std::vector<std::string>> bind; // variable -> rig paths
    std::vector<ExperimentTest> tests;
    std::vector<ChartSpec> charts;
};

// Reads and validates an experiment, including every test's resulting rig against the
// plugins `host` found. Throws binocle::Error with file, line and reason; nothing runs.
Experiment loadExperiment(const std::string &file, const PluginHost &host);

// An experiment made in code: the base rig file and one test per geometry (ids 1, 2 ...),
// bound to the rig the same way as a file without `bind:`. Validated like a file.
Experiment makeExperiment(const std::string &name, const std::string &rig_file, const std::vector<TestGeometry> &tests,
                          const PluginHost &host);

// The rig of one test: the base rig with the test's variables and overrides applied.
YAML::Node rigForTest(const Experiment &e, const ExperimentTest &t);

struct ExperimentOptions {
    std::string out_dir;
    bool progress = true;
    std::vector<std::string> only; // test ids to run; empty = all
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
};

// Runs every test and writes results.csv, results.json, charts and per-test outputs
// into out_dir/test_<id>/. Returns the rows it wrote. A test whose pipeline fails is
// recorded with its error and the others still run; the caller decides the exit status
// from `failed`.
ExperimentResult runExperiment(const Experiment &e, const PluginHost &host, const ExperimentOptions &options);

} // namespace binocle
