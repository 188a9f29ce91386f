// SPDX-License-Identifier: MIT
// `binocle run RIG.yaml`: runs the pipeline of a rig and writes its outputs.
#include "cli/command.hpp"
#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "pipeline/pipeline.hpp"
#include "pipeline/stop_signal.hpp"

#include <iostream>

namespace binocle::cli {
namespace {

int run(const Args &args) {
    if (args.positional().size() != 1) throw Error("expected one rig file: binocle run RIG.yaml (see --help)");
    PluginHost host;
    host.scan();
    RigConfig rig = loadRigFromArgs(args, host);
    RunOptions options;
    options.max_frames = args.integer("--frames", -1);
    options.out_dir = args.get("--out", "");
    options.progress = !args.has("--quiet");
    Pipeline pipeline(rig, host);
    StopSignalGuard signals; // Ctrl-C / SIGTERM: finish the frames in flight, write the summary
    options.stop = &StopSignalGuard::requested();
    const nlohmann::ordered_json summary = pipeline.run(options);
    std::cerr << "binocle run: " << summary.value("frame_count", int64_t{0}) << " frame(s) of rig '" << rig.name << "'";
    if (summary.value("status", "") == "interrupted") std::cerr << " (interrupted)";
    if (!options.out_dir.empty()) std::cerr << " written to " << options.out_dir << " (summary.json)";
    std::cerr << "\n";
    if (options.out_dir.empty()) std::cout << summary.dump(2) << "\n";
    // Interrupted: the usual 128 + signal, though everything finished was written.
    return summary.value("status", "") == "interrupted" ? 128 + StopSignalGuard::signalNumber() : 0;
}

Register reg({"run", "run a rig: disparity, cloud in ground coordinates, evaluators",
              "usage: binocle run RIG.yaml [--frames N] [--out DIR] [--set KEY=VALUE]... [--quiet]\n\n"
              "Runs the rig's pipeline: acquire -> rectify -> disparity -> cloud -> transforms\n"
              "-> evaluators. Per frame it writes into DIR:\n"
              "  disparity_NNNNNN.png        16-bit disparity, KITTI convention (d * 256, 0 = invalid)\n"
              "  disparity_color_NNNNNN.png  colourised disparity (invalid = black)\n"
              "  cloud_NNNNNN.ply            binary PLY, millimetres, frame stated in the header\n"
              "and frames.jsonl (one line of figures per frame, written as it finishes) and\n"
              "summary.json (evaluator metrics, drops, status). Without --out the summary goes\n"
              "to standard output. SIGINT/SIGTERM stop the run cleanly (status interrupted);\n"
              "a second signal ends it at once. The rig's runtime: block sets the policy.\n\n"
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
