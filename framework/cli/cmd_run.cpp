// SPDX-License-Identifier: MIT
// `binocle run RIG.yaml`: runs the pipeline of a rig and writes its outputs.
#include "cli/command.hpp"
#include "config/rig_config.hpp"
#include "core/json.hpp"
#include "pipeline/pipeline.hpp"

#include <spdlog/spdlog.h>

#include <iostream>

namespace binocle::cli {
namespace {

struct RunArgs {
    RigArgs rig;
    int64_t frames = -1;
    std::string out;
    bool quiet = false;
};

int runRig(const RunArgs &args) {
    PluginHost host;
    host.scan();
    RigConfig rig = loadRig(args.rig, host);
    RunOptions options;
    options.max_frames = args.frames;
    options.out_dir = args.out;
    options.progress = !args.quiet;
    Pipeline pipeline(rig, host);
    Json summary = pipeline.run(options);
    spdlog::info("binocle run: {} frame(s) of rig '{}'{}", summary.value("frame_count", int64_t{0}), rig.name,
                 options.out_dir.empty() ? "" : " written to " + options.out_dir + " (summary.json)");
    if (options.out_dir.empty()) std::cout << dumpJson(summary);
    return 0;
}

Register reg{{"run", "run a rig: disparity, cloud in ground coordinates, evaluators",
              "Runs the rig's pipeline: acquire -> rectify -> disparity -> cloud -> transforms\n"
              "-> evaluators. Per frame it writes into DIR:\n"
              "  disparity_NNNNNN.png        16-bit disparity, KITTI convention (d * 256, 0 = invalid)\n"
              "  disparity_color_NNNNNN.png  colourised disparity (invalid = black)\n"
              "  cloud_NNNNNN.ply            binary PLY, millimetres, frame stated in the header\n"
              "and summary.json (per-frame figures, evaluator metrics, status). Without --out\n"
              "the summary goes to standard output.\n"
              "Example: binocle run RIG.yaml --frames 10 --set matcher.num_disparities=128 --set transforms.0.inclination_deg=10",
              [](CLI::App &app) -> Runner {
                  auto args = std::make_shared<RunArgs>();
                  addRigArgs(app, args->rig);
                  app.add_option("--frames", args->frames, "stop after N frames (default: until the source ends)")
                      ->type_name("N")
                      ->check(atLeast(1));
                  app.add_option("--out", args->out, "output folder (created if needed)")->type_name("DIR");
                  app.add_flag("--quiet", args->quiet, "no progress display");
                  return [args] { return runRig(*args); };
              }}};

} // namespace
} // namespace binocle::cli
