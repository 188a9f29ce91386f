// SPDX-License-Identifier: MIT
// RigRun: the folder, the writers and the stop of one run of a rig.
#include "app/run_rig.hpp"

#include "rosbag/rosbag_run_output.hpp"

#include <filesystem>

namespace binocle::app {

RigRun::RigRun(const RigConfig &rig, const PluginHost &host, RunRequest request) : request_(std::move(request)) {
    if (request_.mcap && request_.out.empty())
        throw RequestError(request_.caller.arg("mcap") + ": expected " + request_.caller.arg("out") +
                           " DIR (the bag goes into DIR/bag)");
    pipeline_ = std::make_unique<Pipeline>(rig, host);
    // Owned until the summary is written: a second run into the same folder is refused,
    // and so is a folder that holds a recording or an experiment (unless forced).
    if (!request_.out.empty()) folder_.emplace(request_.out, request_.caller.claim(OutputKind::Run, request_.force));
    // mcap: the frames also go into DIR/bag, a rosbag2 bag (docs/ros2.md): one more writer
    // of the writer stage, after the folder's.
    if (request_.mcap)
        bag_ = std::make_unique<RosbagFrameWriter>((std::filesystem::path(request_.out) / "bag").string(), request_.rosbag);
}

RigRun::~RigRun() = default;

RunResult RigRun::run(const std::function<void(const FrameResult &)> &onFrame) {
    RunOptions options;
    options.max_frames = request_.frames;
    options.progress = request_.progress;
    options.out_dir = request_.out;
    if (bag_) options.writers.push_back(bag_.get());
    // Ctrl-C / SIGTERM (or the caller's flag): finish the frames in flight, write the summary.
    const StopFlag stop(request_.stop);
    options.stop = stop.flag();
    RunResult result;
    result.summary = pipeline_->run(options, onFrame);
    result.interrupted = result.summary.value("status", "") == "interrupted";
    result.signal = stop.signal();
    return result;
}

void RigRun::release() { folder_.reset(); }

RunResult runRig(const RigConfig &rig, const PluginHost &host, const RunRequest &request) {
    RigRun run(rig, host, request);
    return run.run();
}

} // namespace binocle::app
