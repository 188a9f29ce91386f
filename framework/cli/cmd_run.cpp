// SPDX-License-Identifier: MIT
// `binocle run RIG.yaml`: runs the pipeline of a rig and writes its outputs.
#include "app/run_rig.hpp"
#include "cli/command.hpp"
#include "config/rig_config.hpp"
#include "core/json.hpp"

#include <spdlog/spdlog.h>

#include <iostream>

namespace binocle::cli {
namespace {

struct RunArgs {
    RigArgs rig;
    app::RunRequest request; // frames, out, force, mcap and its rosbag options
    bool quiet = false;
};

int runRig(RunArgs args) {
    PluginHost host;
    // No scan: the rig opens only the plugins it names.
    const RigConfig rig = loadRig(args.rig, host);
    args.request.progress = !args.quiet;
    const app::RunResult result = app::runRig(rig, host, args.request);
    const std::string &out = args.request.out;
    spdlog::info("binocle run: {} frame(s) of rig '{}'{}{}", result.summary.value("frame_count", int64_t{0}), rig.name,
                 result.interrupted ? " (interrupted)" : "", out.empty() ? "" : " written to " + out + " (summary.json)");
    if (out.empty()) std::cout << dumpJson(result.summary);
    // Interrupted: the usual 128 + signal, though everything finished was written.
    return result.interrupted ? 128 + result.signal : 0;
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
                      addFramesOption(app, args.request.frames, "stop after N frames (default: until the source ends)");
                      app.add_option("--out", args.request.out, "output folder (created if needed)")->type_name("DIR");
                      app.add_flag("--force", args.request.force,
                                   "replace what --out holds when it is another kind of output (a recording, an experiment)");
                      app.add_flag("--quiet", args.quiet, "no progress display");
                      app.add_flag("--mcap", args.request.mcap,
                                   "also write DIR/bag, a rosbag2 MCAP bag: rectified images, DisparityImage, PointCloud2 "
                                   "in the ground frame, figures (docs/ros2.md)");
                      app.add_option("--ros-namespace", args.request.rosbag.ros_namespace, "--mcap: the topics' namespace (default /binocle)")
                          ->type_name("NS")
                          ->check(CLI::Validator(rosNamespaceRefusal, "NS"));
                  },
                  runRig)}};

} // namespace
} // namespace binocle::cli
