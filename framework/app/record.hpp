// SPDX-License-Identifier: MIT
// Recording a rig's source (`binocle record`): the recording's folder claimed, the sink
// chosen by format (the folder of PNG pairs, or a rosbag2 bag), then the recorder run.
#pragma once

#include "app/request.hpp"
#include "config/rig_config.hpp"
#include "pipeline/recorder.hpp"
#include "rosbag/rosbag_writer.hpp"

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

namespace binocle::app {

struct RecordRequest {
    Caller caller{"binocle record"};
    std::string out;                       // the recording's folder: new or empty (required)
    int64_t frames = -1;                   // pairs taken from the source; < 0: until it ends
    int32_t timeout_ms = 5000;             // longest wait for one frame
    int png_compression = 1;               // zlib level 0..9 of the folder's PNG images
    int writer_threads = 0;                // 0: the writer's default
    std::optional<bool> drop_when_behind;  // unset: from the source (drop when live)
    bool progress = true;
    std::string format = "folder";         // folder | mcap
    RosbagOptions rosbag;                  // mcap's topics and frame ids
    // Set from elsewhere to stop cleanly. Null: SIGINT, SIGTERM and SIGHUP stop the
    // recording (StopSignalGuard; a second signal ends the process).
    const std::atomic<bool> *stop = nullptr;
};

// Records rig.source into request.out. Refusals (no folder, an unknown format, bad mcap
// options, a folder that holds anything) are thrown before anything is recorded; a failure
// of the source once it started is returned in RecordResult::error (what is written stays
// readable).
RecordResult record(const RigConfig &rig, const RecordRequest &request);

} // namespace binocle::app
