// SPDX-License-Identifier: MIT
// `binocle record RIG.yaml --out DIR`: records a rig's source to a folder that the replay
// plugin plays back (layout `recording`, plugins/replay/README.md).
#include "app/record.hpp"
#include "cli/command.hpp"
#include "config/rig_config.hpp"

#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include <iostream>

namespace binocle::cli {
namespace {

struct RecordArgs {
    RigArgs rig;
    app::RecordRequest request; // out, frames, timeout, PNG level, writers, format and its rosbag options
    std::string when_behind;    // empty: from the source (drop when live)
    bool statistics = false, quiet = false;
};

int record(RecordArgs args) {
    PluginHost host;
    // No scan: the rig opens only the plugins it names.
    const RigConfig rig = loadRig(args.rig, host);
    args.request.progress = !args.quiet;
    if (!args.when_behind.empty()) args.request.drop_when_behind = args.when_behind == "drop";
    const RecordResult r = app::record(rig, args.request);
    const std::string &out = args.request.out;
    spdlog::info("binocle record: {} frame(s) of rig '{}' recorded to {} in {} s", r.frames, rig.name, out, r.seconds);
    // Where every pair that was not written went (also in DIR/summary.json).
    const nlohmann::ordered_json lost = recordingSummary(r)["lost"];
    std::string where = "binocle record: " + std::to_string(r.grabbed) + " pair(s) taken from the source, " +
                        std::to_string(r.dropped_by_writer) + " dropped because the writers were behind (" +
                        lost["when_writers_behind"].get<std::string>() + " when behind)";
    if (lost.contains("unpaired_images")) where += "; source: " + lost["unpaired_images"].dump() + " image(s) left unpaired";
    if (lost.contains("cameras"))
        for (const auto &[role, c] : lost["cameras"].items())
            where += "; " + role + ": " + std::to_string(c.value("images_sent", int64_t{-1})) + " image(s) sent, " +
                     std::to_string(c.value("lost_in_camera_or_transport", int64_t{0})) + " lost in the camera or transport, " +
                     std::to_string(c.value("lost_in_pairing", int64_t{0})) + " in pairing";
    spdlog::info("{}", where);
    if (!r.source_statistics.empty() && args.statistics) std::cout << r.source_statistics;
    if (!r.error.empty()) {
        spdlog::error("{}", r.error);
        spdlog::info("binocle record: the {} frame(s) already written are complete and replayable", r.frames);
        return 1;
    }
    return 0;
}

Register recordCommand{{"record", "record a rig's source (any plugin) to a folder that replay plays back",
              "Records the rig's source, frame by frame, into DIR in the `recording` layout of\n"
              "the replay plugin (plugins/replay/README.md):\n"
              "  left/NNNNNN.png, right/NNNNNN.png   lossless PNG, NNNNNN = the source's sequence\n"
              "  frames.csv        sequence,timestamp_left_ns,timestamp_right_ns,left,right\n"
              "  calibration.yml   the rig's calibration file, else the source's calibration\n"
              "  rig.yaml          the rig as resolved (after --set)\n"
              "Each pair is copied at once (the camera has its buffers back) and encoded and\n"
              "written by a pool of threads (temporary file, fsync, rename); frames.csv rows\n"
              "follow in batches, each row only once its images are durable, and are fsync'ed:\n"
              "a recording cut short (process killed, power lost) plays back up to its last\n"
              "row. summary.json gives the pairs taken, written and lost, and where. Replay it with\n"
              "  source: {plugin: replay, folder: DIR}\n"
              "--format mcap writes a ROS 2 bag instead (docs/ros2.md): DIR/<DIR>_0.mcap (rosbag2\n"
              "MCAP: sensor_msgs/Image and CameraInfo per side under --ros-namespace, zstd chunks,\n"
              "each fsync'ed; summary and footer on a clean stop) and DIR/metadata.yaml, for\n"
              "ros2 bag play, Foxglove, and replay (source: {plugin: replay, bag: DIR}).\n"
              "Example: binocle record RIG.yaml --out recordings/run1 --frames 100 --set source.exposure_us=2000",
              defineOnRig<RecordArgs>(
                  [](CLI::App &app, RecordArgs &args) {
                      app.add_option("--out", args.request.out,
                                     "the recording folder; it must not exist or be empty (an existing recording is never overwritten)")
                          ->type_name("DIR")
                          ->required();
                      addFramesOption(app, args.request.frames, "stop after N pairs from the source (default: until it ends or Ctrl-C)");
                      app.add_option("--timeout-ms", args.request.timeout_ms, "longest wait for one frame (default 5000)")
                          ->type_name("MS")
                          ->check(atLeast(1));
                      app.add_option("--png-compression", args.request.png_compression,
                                     "zlib level 0..9 of the PNG images (default 1: fast, lossless)")
                          ->type_name("L")
                          ->check(wholeNumber())
                          ->check(CLI::Range(0, 9));
                      app.add_option("--writer-threads", args.request.writer_threads,
                                     "threads that encode and write images (default: two per core, 4..16)")
                          ->type_name("N")
                          ->check(atLeast(1));
                      app.add_option("--when-behind", args.when_behind,
                                     "when the writers fall behind: make the source wait, or drop the pair and count it "
                                     "(default: drop for a live source such as cameras, wait for files and simulations)")
                          ->type_name("wait|drop")
                          ->check(CLI::IsMember({"wait", "drop"}));
                      app.add_option("--format", args.request.format,
                                     "folder (PNG + frames.csv, the default) or mcap (a rosbag2 bag: docs/ros2.md)")
                          ->type_name("folder|mcap")
                          ->check(CLI::IsMember({"folder", "mcap"}));
                      app.add_option("--ros-namespace", args.request.rosbag.ros_namespace,
                                     "mcap: the topics' namespace (default /binocle: /binocle/left/image_raw ...)")
                          ->type_name("NS")
                          ->check(CLI::Validator(rosNamespaceRefusal, "NS"));
                      app.add_option("--frame-id-left", args.request.rosbag.frame_id_left,
                                     "mcap: header.frame_id of the left images (default binocle_left_optical)")
                          ->type_name("ID");
                      app.add_option("--frame-id-right", args.request.rosbag.frame_id_right,
                                     "mcap: header.frame_id of the right images (default binocle_right_optical)")
                          ->type_name("ID");
                      app.add_flag("--statistics", args.statistics, "print the source's statistics (YAML) at the end");
                      app.add_flag("--quiet", args.quiet, "no progress display");
                  },
                  record)}};

} // namespace
} // namespace binocle::cli
