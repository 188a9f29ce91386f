// SPDX-License-Identifier: MIT
// An experiment's rows and its tables: results.csv and results.json (with the predictors'
// Spearman rho and the software that produced them). Internal to framework/experiment.
#pragma once

#include "experiment/experiment.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace binocle::experiment {

using OJson = nlohmann::ordered_json;

// Main columns first (the names of METHOD.md), then every other figure an evaluator
// reported, as "<evaluator>.<metric>".
extern const std::vector<std::string> kMainMetrics;
// The figures summarised over repeats (mean, sd, 95 % CI).
extern const std::vector<std::string> kRepeatedMetrics;

// One test's row while the experiment runs (or as a results.json row read back).
struct Row {
    const ExperimentTest *test = nullptr;
    std::vector<std::pair<std::string, double>> values; // in column order
    std::string status = "ok", error;
    OJson details = OJson::object(); // repeats, calibration, paper: results.json only

    double get(const std::string &k) const; // NaN when absent
    void put(const std::string &k, double v);
    OJson toJson() const;
    // From a results.json row (merge): numbers and nulls are values, objects details.
    static Row fromJson(const OJson &j, const ExperimentTest *t);
};

// results.json's `status`: every test of the experiment is there (and the charts);
// the run stopped before its last test (or is still running); the run did a share of
// the tests by design (--tests, --shard) or a merge lacks some (`missing_tests`).
inline constexpr const char *kStatusComplete = "complete";
inline constexpr const char *kStatusInterrupted = "interrupted";
inline constexpr const char *kStatusPartial = "partial";

// What results.json says besides the rows.
struct TablesMeta {
    std::vector<std::string> test_ids; // every test of the experiment, in file order
    int shard_index = 1, shard_count = 1;
    OJson software; // binocle's and the rig's plugins' versions
    std::string status = kStatusComplete;
    std::vector<std::string> missing_tests; // a merge's tests that no folder held
};

TablesMeta metaOf(const Experiment &e, int shardIndex, int shardCount, const PluginHost &host);
// Writes results.csv and results.json into `dir`, each atomically.
void writeTables(const std::string &dir, const Experiment &e, const std::vector<Row> &rows, const TablesMeta &meta);
ExperimentResult resultOf(const std::vector<Row> &rows);

// The experiment file whose results `dir` holds (results.json's `file`); "" when it
// holds none or they cannot be read.
std::string resultsOwner(const std::string &dir);
// Removes what an experiment wrote into `dir` as its results.json lists it: the tables,
// the charts, report.html and the test_<id>/ folders (a planted symlink is removed, never
// followed). Used before a run or a merge replaces them.
void clearResults(const std::string &dir);

} // namespace binocle::experiment
