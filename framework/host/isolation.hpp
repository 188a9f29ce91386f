// SPDX-License-Identifier: MIT
// Plugins out of process: files examined in short-lived children, and matchers run in a
// helper process behind a proxy (libcamera's IPA isolation is the model).
#pragma once

#include "host/plugin_host.hpp"

#include <chrono>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <sys/types.h>
#include <vector>

namespace binocle {

// "signal 11 (SIGSEGV)".
std::string describeSignal(int sig);
// How a child ended, from waitpid's status: "killed by signal 11 (SIGSEGV)", "exited with status 3".
std::string describeExit(int status);

// Opens each file in a child process of its own (at most a few at once); returns the
// reason for each file that failed there: refused by the checks, crashed (the signal), or
// still loading after timeout_ms (killed). Files absent from the map loaded fine.
std::map<std::string, std::string> examineInChildren(const std::vector<std::string> &paths, int32_t timeout_ms);

// The helper executable: $BINOCLE_PLUGIN_HELPER, else <prefix>/libexec/binocle/
// binocle-plugin-helper next to the running executable. Throws Error when absent.
std::string helperExecutable();

// The host's side of a matcher that lives in a helper process. Images cross in a
// shared memory file (memfd), never through the socket; each call has a watchdog
// (call_timeout_ms). A crash or a timeout throws PluginError naming the plugin, the call
// and the signal, or, with `restart`, restarts the helper and leaves that frame without
// disparity.
class MatcherHelper {
public:
    MatcherHelper(const PluginRecord &record, const ParamValues &params);
    ~MatcherHelper();
    MatcherHelper(const MatcherHelper &) = delete;
    MatcherHelper &operator=(const MatcherHelper &) = delete;

    // disparity: CV_32F of left's size, filled by the plugin.
    void compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity);
    std::pair<int32_t, int32_t> disparityRange();
    int32_t restarts() const { return restarts_; }
    pid_t pid() const { return pid_; }

private:
    struct Reply;
    void start();
    void stopHelper();
    // timeout_ms < 0: call_timeout_ms.
    Reply call(const std::string &what, const std::string &request, int fd = -1, int32_t timeout_ms = -1);
    void mapShared(size_t bytes);

    PluginRecord record_;
    ParamValues params_;
    IsolationOptions options_;
    pid_t pid_ = -1;
    int socket_ = -1;
    int memfd_ = -1;
    void *shared_ = nullptr;
    size_t sharedBytes_ = 0;
    bool sharedSent_ = false;
    int32_t restarts_ = 0;
};

// The helper's side: serves the plugin in `path` over socket `fd` until the host hangs
// up. Returns the process exit status.
int serveIsolatedPlugin(int fd, const std::string &path);

} // namespace binocle
