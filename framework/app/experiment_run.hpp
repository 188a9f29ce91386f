// SPDX-License-Identifier: MIT
// Running an experiment (`binocle experiment`, binocle.experiment()) and joining the
// folders of its shards (`binocle experiment merge`): the file and the selection checked,
// the output folder claimed, then the tests run.
#pragma once

#include "app/request.hpp"
#include "core/output_folder.hpp"
#include "experiment/experiment.hpp"
#include "host/plugin_host.hpp"

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace binocle::app {

struct ExperimentRequest {
    Caller caller{"binocle experiment"};
    std::string file;              // the experiment file (YAML)
    std::vector<std::string> set;  // KEY=VALUE changes of the file
    std::vector<std::string> tests; // ids to run; empty: all
    std::string shard;             // "K/N"; empty: every test
    std::string out;               // empty: out/<the experiment's name>
    bool force = false;            // replace another experiment's results in `out`
    bool progress = true;
    // Polled before each test: once true no further test starts (Python's Ctrl-C). Null:
    // every test runs.
    const std::atomic<bool> *stop = nullptr;
};

// The experiment file with every test's rig checked; nothing runs, nothing is written
// (`--check`). A bad change of the file is a RequestError.
Experiment loadExperiment(const ExperimentRequest &request, const PluginHost &host);

// One run of an experiment. The constructor does everything that can refuse the request
// (on the caller's thread): the file loaded and checked, the selection of tests (a bad
// shard or test id is a RequestError), the output folder
// claimed (locked and marked as an experiment's; another kind refused unless `force`).
class ExperimentRun {
public:
    explicit ExperimentRun(const ExperimentRequest &request);
    ~ExperimentRun();
    ExperimentRun(const ExperimentRun &) = delete;
    ExperimentRun &operator=(const ExperimentRun &) = delete;

    const Experiment &experiment() const { return experiment_; }
    const std::string &out() const { return options_.out_dir; } // where the results go
    // Runs the selected tests; their results.csv, results.json, charts and test_<id>/ in out().
    ExperimentResult run();
    // Lets the output folder go (its lock) and closes the plugins; after run().
    void release();

private:
    std::unique_ptr<PluginHost> host_;
    Experiment experiment_;
    ExperimentOptions options_;
    std::optional<OutputFolder> folder_;
};

struct MergeRequest {
    Caller caller{"binocle experiment merge"};
    std::string out;                  // the merged results' folder
    std::vector<std::string> folders; // the shards' output folders
    bool force = false;               // replace the results already in `out`
};

// Joins the folders of the shards into `out`: the same rows as one unsharded run.
ExperimentResult mergeExperiment(const MergeRequest &request);

} // namespace binocle::app
