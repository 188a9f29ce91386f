// SPDX-License-Identifier: MIT
// `binocle view RIG.yaml`: the rig's pipeline with a live web page on this machine.
#include "app/view.hpp"
#include "cli/command.hpp"

#include <nlohmann/json.hpp>

#include <iostream>

namespace binocle::cli {
namespace {

struct ViewArgs {
    RigArgs rig;
    app::ViewRequest request; // the page's options (--out among them), frames, force
};

int view(ViewArgs &args) {
    args.request.rig_file = args.rig.file;
    args.request.overrides = args.rig.overrides;
    const viewer::ViewSummary s = app::view(args.request, [](const std::string &url) {
        std::cout << "binocle view: open " << url << "\n" << std::flush;
    });
    const nlohmann::ordered_json j = {{"frames", s.frames},
                                      {"frames_sent", s.frames_sent},
                                      {"encode_ms_per_frame", s.frames_sent > 0 ? 1000 * s.encode_seconds / s.frames_sent : 0.0},
                                      {"seconds", s.seconds},
                                      {"pipeline_fps", s.pipeline_fps},
                                      {"processing_fps", s.processing_fps},
                                      {"status", s.status}};
    std::cout << j.dump() << "\n";
    return 0;
}

Register viewCommand{{"view", "a live web page of a rig: images, disparity, density views, cloud, figures, controls",
              "Runs the rig's pipeline and serves a page on this machine that shows the rectified\n"
              "images, the colourised disparity (scale in px and m), the top/front/side density\n"
              "views with the objects and panel the evaluators found, the cloud in 3D, and every\n"
              "figure per frame. Its controls come from the plugins' settings tables; a change is\n"
              "validated like --set and applied between frames. Pause, step and snapshot (the\n"
              "frame's outputs, as `binocle run` writes them, into --out).\n"
              "The URL printed at start carries a token that the page's controls need. It serves\n"
              "127.0.0.1 only unless --bind names another address and --allow-remote is given;\n"
              "requests must name the address they arrive on (or localhost on loopback, or an\n"
              "--allow-host name). The page changes plugin settings only, not resource limits;\n"
              "paths it sets stay inside the rig's folders (docs/security.md). Browsers that are\n"
              "slow get fewer frames; the pipeline never waits for them. Ctrl-C stops.\n"
              "Example: binocle view configs/rigs/sim-videre.yaml --port 8080",
              defineOnRig<ViewArgs>(
                  [](CLI::App &app, ViewArgs &args) {
                      addNumber(app, "--port", args.request.options.port, "TCP port (0: any free port)", "N", wholeNumberIn(0, 65535))
                          ->capture_default_str();
                      app.add_option("--bind", args.request.options.address, "address to listen on (an IP address)")
                          ->type_name("ADDR")
                          ->capture_default_str();
                      app.add_flag("--allow-remote", args.request.options.allow_remote,
                                   "serve a --bind address other than loopback (the token then crosses the network in clear)");
                      app.add_option("--allow-host", args.request.options.allowed_hosts,
                                     "a Host name to serve besides the address a request arrives on (a DNS name of this machine)")
                          ->type_name("NAME");
                      app.add_option("--out", args.request.options.out_dir, "where snapshots go")->type_name("DIR")->capture_default_str();
                      app.add_flag("--force", args.request.force, "replace what --out holds when another command (or you) wrote it");
                      addNumber(app, "--display-fps", args.request.options.display_fps,
                                "most frames per second sent to browsers (each gets no more than it can draw)", "F", positiveNumber())
                          ->capture_default_str();
                      addNumber(app, "--cloud-points", args.request.options.cloud_points, "most points drawn in the 3D view (thinned evenly)", "N",
                                atLeast(1))
                          ->capture_default_str();
                      addNumber(app, "--cloud-fps", args.request.options.cloud_fps,
                                "most new clouds per second for the 3D view (the images come at --display-fps)", "F", positiveNumber())
                          ->capture_default_str();
                      addFramesOption(app, args.request.frames, "stop after N frames (measurements)");
                      app.add_flag("--paused", args.request.options.paused, "start paused on the first frame");
                  },
                  view)}};

} // namespace
} // namespace binocle::cli
