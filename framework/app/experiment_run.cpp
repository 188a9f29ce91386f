// SPDX-License-Identifier: MIT
// ExperimentRun and mergeExperiment: the checks and the folder of an experiment's run.
#include "app/experiment_run.hpp"

#include "config/rig_config.hpp"

#include <tuple>

namespace binocle::app {

namespace {

// The options a request asks for, its selection checked against `e`.
ExperimentOptions experimentOptions(const ExperimentRequest &request, const Experiment &e) {
    ExperimentOptions options;
    options.out_dir = request.out.empty() ? "out/" + e.name : request.out;
    options.progress = request.progress;
    options.replace = request.force;
    options.stop = request.stop;
    for (const auto &id : request.tests)
        if (!id.empty()) options.only.push_back(id);
    try { // the shard and the test ids are values the user gave: a mistake there is the request's
        if (!request.shard.empty()) std::tie(options.shard_index, options.shard_count) = parseShard(request.shard);
        selectTests(e, options);
    } catch (const Error &x) {
        throw RequestError(x.what());
    }
    return options;
}

} // namespace

Experiment loadExperiment(const ExperimentRequest &request, const PluginHost &host) {
    Experiment e;
    try {
        e = binocle::loadExperiment(request.file, host, request.set);
    } catch (const OverrideError &x) {
        throw RequestError(x.what()); // a bad change is a bad value of the request
    }
    return e;
}

ExperimentRun::ExperimentRun(const ExperimentRequest &request) : host_(std::make_unique<PluginHost>()) {
    // No scan: the rig opens only the plugins it names. Everything is checked before the
    // first test runs.
    experiment_ = loadExperiment(request, *host_);
    options_ = experimentOptions(request, experiment_);
    folder_.emplace(options_.out_dir, request.caller.claim(OutputKind::Experiment, request.force));
}

ExperimentRun::~ExperimentRun() = default;

ExperimentResult ExperimentRun::run() { return runExperiment(experiment_, *host_, options_); }

void ExperimentRun::release() {
    folder_.reset();
    host_.reset();
}

ExperimentResult mergeExperiment(const MergeRequest &request) {
    PluginHost host;
    host.scan();
    const OutputFolder folder(request.out, request.caller.claim(OutputKind::Experiment, request.force));
    return mergeExperimentResults(request.out, request.folders, host, request.force);
}

} // namespace binocle::app
