// SPDX-License-Identifier: MIT
// Plugin files examined in short-lived children (`binocle plugins --isolated`, the
// conformance kit's load case): a file whose code crashes or hangs at load is refused.
#include "host/child_process.hpp"
#include "host/isolation.hpp"

#include <algorithm>
#include <memory>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

namespace binocle {

namespace {

// The child: open the file with every check of the host and say why it was refused ("" when
// it loaded). Its own stdout goes to stderr so that a chatty constructor cannot garble the
// parent's listing.
std::string examine(const std::string &path) {
    ::dup2(2, 1);
    std::string reason;
    try {
        PluginHost host(std::vector<std::string>{});
        host.load(path);
    } catch (const std::exception &e) {
        reason = e.what();
        const std::string prefix = "plugin file " + path + " refused: ";
        if (reason.rfind(prefix, 0) == 0) reason = reason.substr(prefix.size());
        if (reason.empty()) reason = "refused";
    }
    return reason;
}

// Why the examination of a file refuses it, or "" when it loaded fine.
std::string verdict(const DeadlineChild::End &end, int32_t timeout_ms) {
    if (end.timedOut)
        return "still loading after " + std::to_string(timeout_ms) +
               " ms (a library constructor hangs?); its examination was killed";
    if (WIFSIGNALED(end.status)) return "crashed while loading (its code runs at load): " + describeExit(end.status);
    if (!end.output.empty()) return end.output;
    if (!WIFEXITED(end.status) || WEXITSTATUS(end.status) != 0) return "examination " + describeExit(end.status);
    return "";
}

} // namespace

std::map<std::string, std::string> examineInChildren(const std::vector<std::string> &paths, int32_t timeout_ms) {
    struct Running {
        std::string path;
        std::unique_ptr<DeadlineChild> child;
    };
    std::map<std::string, std::string> refusals;
    constexpr size_t kAtOnce = 8;
    size_t next = 0;
    std::vector<Running> running;
    while (next < paths.size() || !running.empty()) {
        while (next < paths.size() && running.size() < kAtOnce) {
            const std::string path = paths[next++];
            try {
                running.push_back({path, std::make_unique<DeadlineChild>([path] { return examine(path); }, timeout_ms)});
            } catch (const std::exception &e) {
                refusals[path] = std::string("cannot examine: ") + e.what();
            }
        }
        std::vector<pollfd> fds;
        int wait = timeout_ms;
        for (const auto &r : running) {
            fds.push_back({r.child->fd(), POLLIN, 0});
            wait = std::min(wait, r.child->remainingMs());
        }
        ::poll(fds.data(), fds.size(), wait);
        for (size_t i = 0; i < running.size();) {
            DeadlineChild &c = *running[i].child;
            const bool ended = (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) && c.readSome();
            if (ended || c.remainingMs() == 0) {
                if (std::string why = verdict(c.finish(), timeout_ms); !why.empty()) refusals[running[i].path] = why;
                running.erase(running.begin() + static_cast<std::ptrdiff_t>(i));
                fds.erase(fds.begin() + static_cast<std::ptrdiff_t>(i));
            } else {
                ++i;
            }
        }
    }
    return refusals;
}

} // namespace binocle
