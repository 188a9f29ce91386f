// SPDX-License-Identifier: MIT
// record(): the checks, the sink, the folder and the stop of one recording.
#include "app/record.hpp"

#include "core/output_folder.hpp"
#include "rosbag/rosbag_recording.hpp"

namespace binocle::app {

RecordResult record(const RigConfig &rig, const RecordRequest &request) {
    const Caller &caller = request.caller;
    if (request.out.empty()) throw RequestError(caller.arg("out") + ": expected the folder to record into");
    if (request.format != "folder" && request.format != "mcap")
        throw RequestError(caller.shown("format", request.format) + ": expected folder or mcap");
    RecordOptions options;
    options.max_frames = request.frames;
    options.progress = request.progress;
    options.grab_timeout_ms = request.timeout_ms;
    options.writer.png_compression = request.png_compression;
    options.writer.threads = request.writer_threads;
    options.drop_when_behind = request.drop_when_behind;
    // First Ctrl-C (or SIGTERM, SIGHUP): finish the frames being written and stop.
    // Second: die at once (what is written stays readable either way).
    const StopFlag stop(request.stop);
    options.stop = stop.flag();
    checkRosbagOptions(request.rosbag);
    // Where the pairs go: the folder of PNG pairs, or a rosbag2 bag; the recorder names neither.
    options.sink = request.format == "mcap" ? rosbagRecordingSink(request.rosbag) : folderRecordingSink();
    // One recorder per folder, marked as a recording; the writer itself refuses a folder
    // that holds anything (a recording is never written over, forced or not).
    const OutputFolder folder(request.out, caller.claim(OutputKind::Recording, false));
    return recordRig(rig, request.out, options);
}

} // namespace binocle::app
