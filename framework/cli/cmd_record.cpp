// SPDX-License-Identifier: MIT
// `binocle record RIG.yaml --out DIR`: records a rig's source to a folder that the replay
// plugin plays back (layout `recording`, plugins/replay/README.md).
#include "cli/command.hpp"
#include "config/rig_config.hpp"
#include "pipeline/recorder.hpp"

#include <spdlog/spdlog.h>

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

struct RecordArgs {
    RigArgs rig;
    std::string out;
    int64_t frames = -1;
    int32_t timeout_ms = 5000;
    bool statistics = false, quiet = false;
};

int record(const RecordArgs &args) {
    if (args.out.empty()) throw UsageError("--out: expected the folder to record into");
    PluginHost host;
    host.scan();
    RigConfig rig = loadRig(args.rig, host);
    RecordOptions options;
    options.max_frames = args.frames;
    options.grab_timeout_ms = args.timeout_ms;
    options.progress = !args.quiet;
    options.stop = &stopRequested;
    std::signal(SIGINT, onStopSignal);
    std::signal(SIGTERM, onStopSignal);
    RecordResult r = recordRig(rig, args.out, options);
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    spdlog::info("binocle record: {} frame(s) of rig '{}' recorded to {} in {} s", r.frames, rig.name, args.out, r.seconds);
    if (!r.source_statistics.empty() && args.statistics) std::cout << r.source_statistics;
    if (!r.error.empty()) {
        spdlog::error("{}", r.error);
        spdlog::info("binocle record: the {} frame(s) already written are complete and replayable", r.frames);
        return 1;
    }
    return 0;
}

Register reg{{"record", "record a rig's source (any plugin) to a folder that replay plays back",
              "Records the rig's source, frame by frame, into DIR in the `recording` layout of\n"
              "the replay plugin (plugins/replay/README.md):\n"
              "  left/NNNNNN.png, right/NNNNNN.png   lossless PNG, NNNNNN = the source's sequence\n"
              "  frames.csv        sequence,timestamp_left_ns,timestamp_right_ns,left,right\n"
              "  calibration.yml   the rig's calibration file, else the source's calibration\n"
              "  rig.yaml          the rig as resolved (after --set)\n"
              "Each frame's images are written (temporary file, fsync, rename) before its\n"
              "frames.csv line, which is flushed and fsync'ed: a recording cut short (process\n"
              "killed, power lost) plays back up to its last complete frame. Replay it with\n"
              "  source: {plugin: replay, folder: DIR}\n"
              "Example: binocle record RIG.yaml --out recordings/run1 --frames 100 --set source.exposure_us=2000",
              [](CLI::App &app) -> Runner {
                  auto args = std::make_shared<RecordArgs>();
                  addRigArgs(app, args->rig);
                  app.add_option("--out", args->out,
                                 "the recording folder; it must not exist or be empty (an existing recording is never overwritten)")
                      ->type_name("DIR")
                      ->required();
                  app.add_option("--frames", args->frames, "stop after N frames (default: until the source ends or Ctrl-C)")
                      ->type_name("N")
                      ->check(atLeast(1));
                  app.add_option("--timeout-ms", args->timeout_ms, "longest wait for one frame (default 5000)")
                      ->type_name("MS")
                      ->check(atLeast(1));
                  app.add_flag("--statistics", args->statistics, "print the source's statistics (YAML) at the end");
                  app.add_flag("--quiet", args->quiet, "no progress display");
                  return [args] { return record(*args); };
              }}};

} // namespace
} // namespace binocle::cli
