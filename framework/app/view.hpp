// SPDX-License-Identifier: MIT
// Viewing a rig (`binocle view`): the address checked, the snapshots' folder claimed,
// then the rig's pipeline served on a local web page until it stops.
#pragma once

#include "app/request.hpp"
#include "viewer/viewer.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace binocle::app {

struct ViewRequest {
    Caller caller{"binocle view"};
    // The page's address, port, allowed hosts and rates, and out_dir: where snapshots go.
    // Its rig_file, overrides and max_frames are set from the fields below.
    viewer::ViewOptions options;
    std::string rig_file;
    std::vector<std::string> overrides; // KEY=VALUE, as given (`--set`)
    int64_t frames = -1;                // > 0: stop after this many frames (measurements)
    bool force = false;                 // replace another kind of output in options.out_dir
};

// Serves the rig until SIGINT or SIGTERM, or `frames` frames; `listening` receives the
// page's URL (with its token). Refused before any plugin opens, as a RequestError: an
// address that is not an IP address, or one beyond loopback without allow_remote; then,
// as binocle::Error, an out_dir that another command (or another view) holds, or that
// holds another kind of output (unless `force`). A malformed override, or one the rig
// refuses, is a RequestError too. The folder is the view's while it runs: snapshots are
// a run's outputs by name, so written into a run's folder they would replace its frames.
viewer::ViewSummary view(const ViewRequest &request, const std::function<void(const std::string &url)> &listening);

} // namespace binocle::app
