// SPDX-License-Identifier: MIT
// `binocle run RIG.yaml`: runs the pipeline of a rig and writes its outputs.
#include "cli/command.hpp"
#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "pipeline/pipeline.hpp"

#include <iostream>

namespace binocle::cli {
namespace {

int run(const Args &args) {
    if (args.positional().size() != 1) throw Error("expected one rig file: binocle run RIG.yaml (see --help)");
    PluginHost host;
    // No scan: the rig opens only the plugins it names.
    RigConfig rig = loadRigFromArgs(args, host);
    RunOptions options;
    options.max_frames = args.integer("--frames", -1);
    options.out_dir = args.get("--out", "");
    options.progress = !args.has("--quiet");
    Pipeline pipeline(rig, host);
    Json summary = pipeline.run(options);
    const Json *count = summary.get("frame_count");
    std::cerr << "binocle run: " << (count ? count->number() : 0) << " frame(s) of rig '" << rig.name << "'";
    if (!options.out_dir.empty()) std::cerr << " written to " << options.out_dir << " (summary.json)";
    std::cerr << "\n";
    if (options.out_dir.empty()) std::cout << summary.dump();
    return 0;
}

Register reg({"run", "run a rig: disparity, cloud in ground coordinates, evaluators",
              "usage: binocle run RIG.yaml [--frames N] [--out DIR] [--set KEY=VALUE]... [--quiet]\n\n"
              "Runs the rig's pipeline: acquire -> rectify -> disparity -> cloud -> transforms\n"
              "-> evaluators. Per frame it writes into DIR:\n"
              "  disparity_NNNNNN.png        16-bit disparity, KITTI convention (d * 256, 0 = invalid)\n"
              "  disparity_color_NNNNNN.png  colourised disparity (invalid = black)\n"
              "  cloud_NNNNNN.ply            binary PLY, millimetres, frame stated in the header\n"
              "and summary.json (per-frame figures, evaluator metrics, status). Without --out\n"
              "the summary goes to standard output.\n\n"
              "  --frames N          stop after N frames (default: until the source ends)\n"
              "  --out DIR           output folder (created if needed)\n"
              "  --set KEY=VALUE     override any value of the rig, e.g.\n"
              "                      --set matcher.num_disparities=128\n"
              "                      --set transforms.0.inclination_deg=10\n"
              "  --quiet             no progress line\n",
              {"--quiet"},
              run});

} // namespace
} // namespace binocle::cli
