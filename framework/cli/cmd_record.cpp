// SPDX-License-Identifier: MIT
// `binocle record RIG.yaml --out DIR`: records a rig's source to a folder that the replay
// plugin plays back (layout `recording`, plugins/replay/README.md).
#include "cli/command.hpp"
#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "pipeline/recorder.hpp"

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
    // No scan: the rig opens only the plugins it names.
    RigConfig rig = loadRigFromArgs(args, host);
    RecordOptions options;
    options.max_frames = args.integer("--frames", -1);
    if (args.has("--frames") && options.max_frames < 1)
        throw Error("option --frames = " + args.get("--frames") + ": expected a positive number of frames");
    options.grab_timeout_ms = static_cast<int32_t>(args.integer("--timeout-ms", 5000));
    options.progress = !args.has("--quiet");
    options.stop = &stopRequested;
    std::signal(SIGINT, onStopSignal);
    std::signal(SIGTERM, onStopSignal);
    const std::string dir = args.get("--out");
    RecordResult r = recordRig(rig, dir, options);
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    std::cerr << "binocle record: " << r.frames << " frame(s) of rig '" << rig.name << "' recorded to " << dir << " in " << r.seconds
              << " s\n";
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
              "Each frame's images are written (temporary file, fsync, rename) before its\n"
              "frames.csv line, which is flushed and fsync'ed: a recording cut short (process\n"
              "killed, power lost) plays back up to its last complete frame. Replay it with\n"
              "  source: {plugin: replay, folder: DIR}\n\n"
              "  --out DIR           the recording folder; it must not exist or be empty\n"
              "                      (an existing recording is never overwritten)\n"
              "  --frames N          stop after N frames (default: until the source ends or Ctrl-C)\n"
              "  --set KEY=VALUE     override any value of the rig, e.g. --set source.exposure_us=2000\n"
              "  --timeout-ms MS     longest wait for one frame (default 5000)\n"
              "  --statistics        print the source's statistics (YAML) at the end\n"
              "  --quiet             no progress line\n",
              {"--quiet", "--statistics"},
              run});

} // namespace
} // namespace binocle::cli
