// SPDX-License-Identifier: MIT
// view(): the bind checks, the snapshots' folder and the viewer of one rig.
#include "app/view.hpp"

#include "core/output_folder.hpp"
#include "viewer/web_guard.hpp"

#include <arpa/inet.h>

namespace binocle::app {
namespace {

// The address to listen on, read before any plugin opens: a mistake in it is a bad
// request (exit status 2), not a failed view.
void checkBind(const Caller &caller, const viewer::ViewOptions &o) {
    unsigned char bytes[16];
    if (::inet_pton(AF_INET, o.address.c_str(), bytes) != 1 && ::inet_pton(AF_INET6, o.address.c_str(), bytes) != 1)
        throw RequestError(caller.shown("bind", o.address) + ": expected an IP address, e.g. 127.0.0.1 or ::1 (not a name)");
    if (const std::string refusal = viewer::remoteBindRefusal(o.address, o.allow_remote); !refusal.empty())
        throw RequestError(refusal);
}

} // namespace

viewer::ViewSummary view(const ViewRequest &request, const std::function<void(const std::string &url)> &listening) {
    viewer::ViewOptions o = request.options;
    checkBind(request.caller, o);
    o.rig_file = request.rig_file;
    o.max_frames = request.frames;
    // out_dir is the view's while it runs; made again, and gone when no snapshot was taken.
    const OutputFolder folder(o.out_dir, request.caller.claim(OutputKind::View, request.force));
    PluginHost host;
    host.scan();
    try {
        for (const auto &text : request.overrides) o.overrides.push_back(Override::parse(text));
        // The rig with the request's overrides is loaded before the page opens: a bad one
        // escapes from there only, never from the page's own commands.
        return viewer::runView(o, host, listening);
    } catch (const OverrideError &e) {
        throw RequestError(e.what()); // a bad override is a bad value of the request, as in a run
    }
}

} // namespace binocle::app
