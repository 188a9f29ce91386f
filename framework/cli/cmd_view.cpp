// SPDX-License-Identifier: MIT
// `binocle view RIG.yaml`: the rig's pipeline with a live web page on this machine.
#include "cli/command.hpp"
#include "core/error.hpp"
#include "viewer/viewer.hpp"

#include <nlohmann/json.hpp>

#include <iostream>

namespace binocle::cli {
namespace {

int view(const Args &args) {
    if (args.positional().size() != 1) throw Error("expected one rig file: binocle view RIG.yaml (see --help)");
    viewer::ViewOptions o;
    o.rig_file = args.positional()[0];
    for (const auto &s : args.all("--set")) o.overrides.push_back(Override::parse(s));
    o.address = args.get("--bind", o.address);
    const long long port = args.integer("--port", o.port);
    if (port < 0 || port > 65535) throw Error("--port " + std::to_string(port) + ": expected 0 .. 65535 (0: any free port)");
    o.port = static_cast<int>(port);
    o.out_dir = args.get("--out", o.out_dir);
    o.display_fps = args.real("--display-fps", o.display_fps);
    if (!(o.display_fps > 0)) throw Error("--display-fps " + args.get("--display-fps") + ": expected a positive number");
    o.max_frames = args.integer("--frames", -1);
    o.paused = args.has("--paused");
    PluginHost host;
    host.scan();
    const viewer::ViewSummary s = viewer::runView(o, host, [](const std::string &url) {
        std::cout << "binocle view: open " << url << "\n" << std::flush;
    });
    nlohmann::ordered_json j = {{"frames", s.frames},          {"frames_sent", s.frames_sent},
                                {"seconds", s.seconds},        {"pipeline_fps", s.pipeline_fps},
                                {"processing_fps", s.processing_fps}, {"status", s.status}};
    std::cout << j.dump() << "\n";
    return 0;
}

Register reg({"view", "a live web page of a rig: images, disparity, density views, cloud, figures, controls",
              "usage: binocle view RIG.yaml [--port N] [--bind ADDR] [--set KEY=VALUE]... [--out DIR]\n"
              "                   [--display-fps F] [--frames N] [--paused]\n\n"
              "Runs the rig's pipeline and serves a page on this machine that shows the rectified\n"
              "images, the colourised disparity (scale in px and m), the top/front/side density\n"
              "views with the objects and panel the evaluators found, the cloud in 3D, and every\n"
              "figure per frame. Its controls come from the plugins' settings tables; a change is\n"
              "validated like --set and applied between frames. Pause, step and snapshot (the\n"
              "frame's outputs, as `binocle run` writes them, into --out).\n\n"
              "The URL printed at start carries a token that the page's controls need. Only\n"
              "requests naming this machine (localhost, 127.0.0.1, ::1) are served. Browsers that\n"
              "are slow get fewer frames; the pipeline never waits for them. Ctrl-C stops.\n\n"
              "  --port N           TCP port (default 8080; 0: any free port)\n"
              "  --bind ADDR        address to listen on (default 127.0.0.1)\n"
              "  --set KEY=VALUE    override any value of the rig (as for run)\n"
              "  --out DIR          where snapshots go (default out/view)\n"
              "  --display-fps F    most frames per second sent to browsers (default 15)\n"
              "  --frames N         stop after N frames (measurements)\n"
              "  --paused           start paused on the first frame\n",
              {"--paused"},
              view});

} // namespace
} // namespace binocle::cli
