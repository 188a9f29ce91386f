// SPDX-License-Identifier: MIT
// Running a rig (`binocle run`, binocle.Rig.run): its output folder claimed, its writers
// chosen (the folder's, and with mcap the bag's), then the pipeline run.
#pragma once

#include "app/request.hpp"
#include "config/rig_config.hpp"
#include "core/output_folder.hpp"
#include "pipeline/pipeline.hpp"
#include "rosbag/rosbag_writer.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace binocle::app {

struct RunRequest {
    Caller caller{"binocle run"};
    int64_t frames = -1;  // < 0: until the source ends
    std::string out;      // empty: nothing written (the summary is returned only)
    bool force = false;   // replace another kind of output in `out`
    bool progress = true; // a progress line on stderr
    bool mcap = false;    // also `out`/bag, a rosbag2 MCAP bag (docs/ros2.md); needs `out`
    RosbagOptions rosbag;
    // Set from elsewhere to stop cleanly. Null: SIGINT, SIGTERM and SIGHUP stop the run
    // while it runs (StopSignalGuard; a second signal ends the process).
    const std::atomic<bool> *stop = nullptr;
};

struct RunResult {
    nlohmann::ordered_json summary; // as summary.json
    bool interrupted = false;       // stopped (a signal, `stop`) before the source ended
    int signal = 0;                 // the signal that stopped it, when the run listened for them
};

// A run of one rig. The constructor does everything that can refuse the request (on the
// caller's thread): the pipeline's plugins are made, the output folder is claimed (locked
// and marked as a run's; another kind of output refused unless `force`), the bag opened.
class RigRun {
public:
    RigRun(const RigConfig &rig, const PluginHost &host, RunRequest request);
    ~RigRun();
    RigRun(const RigRun &) = delete;
    RigRun &operator=(const RigRun &) = delete;

    // Runs until the source ends, `frames` are done or a stop; `onFrame` as Pipeline::run's.
    // Throws binocle::Error after writing the summary when the run failed.
    RunResult run(const std::function<void(const FrameResult &)> &onFrame = {});
    // Lets the output folder go (its lock); after run().
    void release();

private:
    RunRequest request_;
    std::unique_ptr<Pipeline> pipeline_;
    std::optional<OutputFolder> folder_;
    std::unique_ptr<FrameWriter> bag_;
};

// A RigRun made and run.
RunResult runRig(const RigConfig &rig, const PluginHost &host, const RunRequest &request);

} // namespace binocle::app
