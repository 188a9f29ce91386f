// SPDX-License-Identifier: MIT
// `binocle record RIG.yaml --out DIR`: records a rig's source to a folder that the replay
// plugin plays back (layout `recording`, plugins/replay/README.md).
#include "cli/command.hpp"
#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "pipeline/recorder.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <csignal>
#include <iostream>

namespace binocle::cli {
namespace {

std::atomic<bool> stopRequested{false};

// First Ctrl-C (or SIGTERM): finish the frame being written and stop. Second: die at once
// (what is written stays readable either way).
extern "C" void onStopSignal(int sig) {
    if (stopRequested.exchange(true)) {
        std::signal(sig, SIG_DFL);
        std::raise(sig);
    }
}

int run(const Args &args) {
    if (args.positional().size() != 1) throw Error("expected one rig file: binocle record RIG.yaml --out DIR (see --help)");
    if (!args.has("--out") || args.get("--out").empty()) throw Error("missing --out DIR: the folder to record into");
    PluginHost host;
    host.scan();
    RigConfig rig = loadRigFromArgs(args, host);
    RecordOptions options;
    options.max_frames = args.integer("--frames", -1);
    if (args.has("--frames") && options.max_frames < 1)
        throw Error("option --frames = " + args.get("--frames") + ": expected a positive number of frames");
    options.grab_timeout_ms = static_cast<int32_t>(args.integer("--timeout-ms", 5000));
    options.progress = !args.has("--quiet");
    options.stop = &stopRequested;
    options.writer.png_compression = static_cast<int>(args.integer("--png-compression", 1));
    if (options.writer.png_compression < 0 || options.writer.png_compression > 9)
        throw Error("option --png-compression = " + args.get("--png-compression") + ": expected a zlib level 0..9");
    options.writer.threads = static_cast<int>(args.integer("--writer-threads", 0));
    if (args.has("--writer-threads") && options.writer.threads < 1)
        throw Error("option --writer-threads = " + args.get("--writer-threads") + ": expected a positive number of threads");
    if (args.has("--when-behind")) {
        const std::string w = args.get("--when-behind");
        if (w != "wait" && w != "drop") throw Error("option --when-behind = " + w + ": expected wait or drop");
        options.drop_when_behind = w == "drop";
    }
    std::signal(SIGINT, onStopSignal);
    std::signal(SIGTERM, onStopSignal);
    const std::string dir = args.get("--out");
    RecordResult r = recordRig(rig, dir, options);
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    std::cerr << "binocle record: " << r.frames << " frame(s) of rig '" << rig.name << "' recorded to " << dir << " in " << r.seconds
              << " s\n";
    // Where every pair that was not written went (also in DIR/summary.json).
    const nlohmann::ordered_json lost = recordingSummary(r)["lost"];
    std::cerr << "binocle record: " << r.grabbed << " pair(s) taken from the source, " << r.dropped_by_writer
              << " dropped because the writers were behind (" << lost["when_writers_behind"].get<std::string>() << " when behind)";
    if (lost.contains("unpaired_images")) std::cerr << "; source: " << lost["unpaired_images"] << " image(s) left unpaired";
    if (lost.contains("cameras"))
        for (const auto &[role, c] : lost["cameras"].items())
            std::cerr << "; " << role << ": " << c.value("images_sent", int64_t{-1}) << " image(s) sent, "
                      << c.value("lost_in_camera_or_transport", int64_t{0}) << " lost in the camera or transport, "
                      << c.value("lost_in_pairing", int64_t{0}) << " in pairing";
    std::cerr << "\n";
    if (!r.source_statistics.empty() && args.has("--statistics")) std::cout << r.source_statistics;
    if (!r.error.empty()) {
        std::cerr << "binocle record: error: " << r.error << "\nbinocle record: the " << r.frames
                  << " frame(s) already written are complete and replayable\n";
        return 1;
    }
    return 0;
}

Register reg({"record", "record a rig's source (any plugin) to a folder that replay plays back",
              "usage: binocle record RIG.yaml --out DIR [--frames N] [--set KEY=VALUE]... [--quiet]\n\n"
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
              "  source: {plugin: replay, folder: DIR}\n\n"
              "  --out DIR           the recording folder; it must not exist or be empty\n"
              "                      (an existing recording is never overwritten)\n"
              "  --frames N          stop after N pairs from the source (default: until it ends or Ctrl-C)\n"
              "  --set KEY=VALUE     override any value of the rig, e.g. --set source.exposure_us=2000\n"
              "  --timeout-ms MS     longest wait for one frame (default 5000)\n"
              "  --png-compression L zlib level 0..9 of the PNG images (default 1: fast, lossless)\n"
              "  --writer-threads N  threads that encode and write images (default: two per core, 4..16)\n"
              "  --when-behind wait|drop  when the writers fall behind: make the source wait, or drop\n"
              "                      the pair and count it (default: drop for a live source such as\n"
              "                      cameras, wait for files and simulations)\n"
              "  --statistics        print the source's statistics (YAML) at the end\n"
              "  --quiet             no progress line\n",
              {"--quiet", "--statistics"},
              run});

} // namespace
} // namespace binocle::cli
