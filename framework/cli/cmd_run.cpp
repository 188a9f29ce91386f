// SPDX-License-Identifier: MIT
// `binocle run RIG.yaml`: runs the pipeline of a rig and writes its outputs.
#include "cli/command.hpp"
#include "config/rig_config.hpp"
#include "core/json.hpp"
#include "core/output_folder.hpp"
#include "pipeline/pipeline.hpp"
#include "pipeline/stop_signal.hpp"
#include "rosbag/rosbag_run_output.hpp"

#include <filesystem>
#include <memory>
#include <optional>

#include <spdlog/spdlog.h>

#include <iostream>

namespace binocle::cli {
namespace {

struct RunArgs {
    RigArgs rig;
    int64_t frames = -1;
    std::string out;
    bool quiet = false, force = false;
    bool mcap = false;
    RosbagOptions rosbag;
};

int runRig(const RunArgs &args) {
    PluginHost host;
    // No scan: the rig opens only the plugins it names.
    RigConfig rig = loadRig(args.rig, host);
    RunOptions options = framesAndProgress<RunOptions>(args.frames, args.quiet);
    options.out_dir = args.out;
    Pipeline pipeline(rig, host);
    // Owned until the summary is written: a second run into the same folder is refused,
    // and so is a folder that holds a recording or an experiment (unless --force).
    std::optional<OutputFolder> folder;
    if (!args.out.empty()) folder.emplace(args.out, OutputClaim{OutputKind::Run, args.force, "binocle run"});
    StopSignalGuard signals; // Ctrl-C / SIGTERM: finish the frames in flight, write the summary
    options.stop = &StopSignalGuard::requested();
    // --mcap: the frames also go into DIR/bag, a rosbag2 bag (docs/ros2.md): one more
    // writer of the writer stage, after the folder's.
    std::unique_ptr<FrameWriter> bag;
    if (args.mcap && options.out_dir.empty()) throw UsageError("--mcap: expected --out DIR (the bag goes into DIR/bag)");
    if (args.mcap) {
        bag = std::make_unique<RosbagFrameWriter>((std::filesystem::path(options.out_dir) / "bag").string(), args.rosbag);
        options.writers.push_back(bag.get());
    }
    Json summary = pipeline.run(options);
    const bool interrupted = summary.value("status", "") == "interrupted";
    spdlog::info("binocle run: {} frame(s) of rig '{}'{}{}", summary.value("frame_count", int64_t{0}), rig.name,
                 interrupted ? " (interrupted)" : "",
                 options.out_dir.empty() ? "" : " written to " + options.out_dir + " (summary.json)");
    if (options.out_dir.empty()) std::cout << dumpJson(summary);
    // Interrupted: the usual 128 + signal, though everything finished was written.
    return interrupted ? 128 + StopSignalGuard::signalNumber() : 0;
}

Register runCommand{{"run", "run a rig: disparity, cloud in ground coordinates, evaluators",
              "Runs the rig's pipeline: acquire -> rectify -> disparity -> cloud -> transforms\n"
              "-> evaluators. Per frame it writes into DIR:\n"
              "  disparity_NNNNNN.png        16-bit disparity, KITTI convention (d * 256, 0 = invalid)\n"
              "  disparity_color_NNNNNN.png  colourised disparity (invalid = black)\n"
              "  cloud_NNNNNN.ply            binary PLY, millimetres, frame stated in the header\n"
              "  bag/                        with --mcap: a rosbag2 MCAP bag of the rectified\n"
              "                              images, DisparityImage, PointCloud2 and figures (docs/ros2.md)\n"
              "and frames.jsonl (one line of figures per frame, written as it finishes) and\n"
              "summary.json (evaluator metrics, drops, status). Without --out the summary goes\n"
              "to standard output. One process writes into DIR at a time; a DIR that holds a\n"
              "recording or an experiment is refused unless --force (which empties it first).\n"
              "SIGINT/SIGTERM/SIGHUP stop the run cleanly (status interrupted, exit\n"
              "128 + signal); a second signal ends it at once. The rig's runtime: block sets the\n"
              "policy (README \"Runtime\").\n"
              "Example: binocle run RIG.yaml --frames 10 --set matcher.num_disparities=128 --set transforms.0.inclination_deg=10",
              defineOnRig<RunArgs>(
                  [](CLI::App &app, RunArgs &args) {
                      addFramesOption(app, args.frames, "stop after N frames (default: until the source ends)");
                      app.add_option("--out", args.out, "output folder (created if needed)")->type_name("DIR");
                      app.add_flag("--force", args.force,
                                   "replace what --out holds when it is another kind of output (a recording, an experiment)");
                      app.add_flag("--quiet", args.quiet, "no progress display");
                      app.add_flag("--mcap", args.mcap,
                                   "also write DIR/bag, a rosbag2 MCAP bag: rectified images, DisparityImage, PointCloud2 "
                                   "in the ground frame, figures (docs/ros2.md)");
                      app.add_option("--ros-namespace", args.rosbag.ros_namespace, "--mcap: the topics' namespace (default /binocle)")
                          ->type_name("NS")
                          ->check(CLI::Validator(rosNamespaceRefusal, "NS"));
                  },
                  runRig)}};

} // namespace
} // namespace binocle::cli
