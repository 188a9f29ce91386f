// SPDX-License-Identifier: MIT
// `binocle view`: the rig's pipeline on a thread of its own, observed by a local web
// page (server.hpp) that shows every product and changes settings between frames.
#pragma once

#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace binocle::viewer {

struct ViewOptions {
    std::string rig_file;
    std::vector<Override> overrides; // --set, before any change made in the page
    std::string address = "127.0.0.1";
    bool allow_remote = false;       // a non-loopback address is refused without it
    std::vector<std::string> allowed_hosts; // Host names served besides the address (--allow-host)
    int port = 8080;                 // 0: any free port
    std::string out_dir = "out/view"; // where snapshots go
    double display_fps = 2;          // most frames per second sent to the browsers
    size_t cloud_points = 20000;     // most points of the 3D view (the cloud thinned evenly)
    double cloud_fps = 1;            // most new clouds per second for the 3D view
    int64_t max_frames = -1;         // > 0: stop after this many frames (measurements)
    bool paused = false;             // start paused (the first frame is shown)
};

// What a view did, for the closing line and for measurements.
struct ViewSummary {
    int64_t frames = 0;          // processed by the pipeline
    int64_t frames_sent = 0;     // encoded for the browsers
    double encode_seconds = 0;   // spent encoding them (the viewer's own thread)
    double seconds = 0;          // from the first frame's start to the last frame's end
    double pipeline_fps = 0;     // frames / seconds
    double processing_fps = 0;   // frames / time spent inside the pipeline's steps
    std::string status;          // "stopped", "ended", "failed: ..."
};

// Serves until SIGINT or SIGTERM, or until max_frames frames. `listening` receives the
// URL (with its token) once the server accepts connections. Throws binocle::Error when
// the rig is invalid, the address cannot be bound, or it is not a loopback address and
// allow_remote is not set. Warns when it runs as root or serves beyond loopback.
ViewSummary runView(const ViewOptions &options, const PluginHost &host,
                    const std::function<void(const std::string &url)> &listening);

} // namespace binocle::viewer
