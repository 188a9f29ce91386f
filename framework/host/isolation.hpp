// SPDX-License-Identifier: MIT
// Plugins out of process: files examined in short-lived children, and plugins of any kind
// run in a helper process behind a proxy (libcamera's IPA isolation is the model).
#pragma once

#include "host/helper_protocol.hpp"
#include "host/plugin_host.hpp"

#include <chrono>
#include <functional>
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

// A plugin file's header and settings table, read by a helper process: none of the
// file's code runs in this one (its library constructors included). Throws Error with the
// reason when the helper refuses the file, crashes on it (the signal) or is still loading
// it after timeout_ms (killed). The record has no library (`described`).
PluginRecord describeInHelper(const std::string &path, int32_t timeout_ms);

// A shared memory file (memfd) mapped in this process; the helper maps the same file.
class SharedRegion {
public:
    SharedRegion(std::string name, uint32_t id) : name_(std::move(name)), id_(id) {}
    ~SharedRegion();
    SharedRegion(const SharedRegion &) = delete;
    SharedRegion &operator=(const SharedRegion &) = delete;
    // At least `bytes` long; a larger need makes a new file (which must be sent again).
    uint8_t *reserve(size_t bytes);
    uint8_t *data() const { return static_cast<uint8_t *>(data_); }
    size_t size() const { return bytes_; }
    int fd() const { return fd_; }
    uint32_t id() const { return id_; }
    uint64_t sentTo = 0; // the helper generation that has this file mapped (0: none)

private:
    std::string name_;
    uint32_t id_;
    int fd_ = -1;
    void *data_ = nullptr;
    size_t bytes_ = 0;
};

// The host's side of a plugin instance that lives in a helper process: spawns
// binocle-plugin-helper, creates the instance there, makes each call with a watchdog
// (call_timeout_ms), and forwards what the plugin logs and reports to the instance's
// binocle_host, so that its messages read "[plugin] ..." as in process. Pixels cross in
// SharedRegions, never through the socket. A crash or a call past its watchdog throws
// PluginError naming the plugin, the call and the signal, or, with `restart`, restarts
// the helper (create again) and the call's result is lost (counted).
class PluginHelper {
public:
    virtual ~PluginHelper();
    PluginHelper(const PluginHelper &) = delete;
    PluginHelper &operator=(const PluginHelper &) = delete;
    int32_t restarts() const { return restarts_; }
    // Calls whose result was lost to a crash or a hang that a restart survived.
    int64_t lostCalls() const { return lost_; }
    pid_t pid() const { return pid_; }

protected:
    // `lost` says what a restart costs the run ("this frame has no disparity").
    PluginHelper(const PluginRecord &record, const ParamValues &params, const binocle_host *host, std::string lost);
    struct Reply;
    // Spawns the helper and creates the instance; throws PluginError.
    void launch();
    // One request; the region's file goes along when this helper has not mapped it yet.
    // timeout_ms < 0: call_timeout_ms; otherwise `limit` says where timeout_ms comes from.
    // A reply other than BINOCLE_OK throws PluginError with the helper's message. Throws
    // HelperGone (internal) when the helper died or was killed.
    Reply call(const char *what, uint32_t op, const std::string &payload = {}, SharedRegion *region = nullptr,
               int32_t timeout_ms = -1, const char *limit = nullptr);
    // Runs `attempt`; true when it completed. When the helper dies during it: with
    // `restart` and restarts left, restarts it and returns false (the result is lost);
    // otherwise throws PluginError.
    bool guarded(const std::function<void()> &attempt);
    // After a restart has created the instance anew (a source starts again).
    virtual void afterRestart() {}
    const PluginRecord &record() const { return record_; }
    const IsolationOptions &options() const { return options_; }
    uint64_t generation() const { return generation_; }
    // Turns a failure to start (launch) into a PluginError; for constructors.
    void launchOrThrow();
    friend PluginRecord describeInHelper(const std::string &path, int32_t timeout_ms);

private:
    void spawn();
    void stopHelper();
    Reply exchange(const std::string &who, const std::string &request, int fd, int32_t timeout_ms,
                   const std::string &limit);
    void dispatch(uint32_t type, helper::Reader &message);
    // Restarts after `gone` while the rig allows; throws PluginError when it does not.
    void recover(const std::string &gone);

    PluginRecord record_;
    ParamValues params_;
    IsolationOptions options_;
    const binocle_host *host_;
    std::string lost_what_;
    pid_t pid_ = -1;
    int socket_ = -1;
    uint64_t generation_ = 0; // one per helper process started
    int32_t restarts_ = 0;
    int64_t lost_ = 0;
    std::string gone_; // why the helper is gone, for calls after a crash
};

class MatcherHelper : public PluginHelper {
public:
    MatcherHelper(const PluginRecord &record, const ParamValues &params, const binocle_host *host);
    ~MatcherHelper() override;
    // disparity: CV_32F of left's size, filled by the plugin.
    void compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity);
    std::pair<int32_t, int32_t> disparityRange();

private:
    SharedRegion shared_;
};

// A restart re-creates the source with the same settings and starts it again when it
// was started: the grab that crashed is lost (counted), and the next frame is the new
// instance's first (a camera's next image; a file source begins again).
class SourceHelper : public PluginHelper {
public:
    SourceHelper(const PluginRecord &record, const ParamValues &params, const binocle_host *host);
    ~SourceHelper() override;
    void start();
    void stop();
    // Waits timeout_ms for a pair; its watchdog is timeout_ms + call_timeout_ms. The frame
    // is a copy in shared memory (the helper gives the plugin its frame back at once);
    // nullptr at end of stream.
    std::unique_ptr<LentFrame> grab(int32_t timeout_ms);
    std::string calibration();
    std::string statistics();

private:
    void afterRestart() override;
    struct Slots;
    std::shared_ptr<Slots> slots_; // shared with the frames still lent
    bool started_ = false;
};

class TransformHelper : public PluginHelper {
public:
    TransformHelper(const PluginRecord &record, const ParamValues &params, const binocle_host *host);
    ~TransformHelper() override;
    // The cloud's arrays cross in shared memory and come back rewritten; after a restart
    // the cloud of that frame is dropped (count 0).
    void apply(binocle_cloud &cloud);

private:
    SharedRegion shared_;
};

class EvaluatorHelper : public PluginHelper {
public:
    EvaluatorHelper(const PluginRecord &record, const ParamValues &params, const binocle_host *host);
    ~EvaluatorHelper() override;
    // Frame, rectified images, disparity and cloud cross in shared memory; the figures the
    // plugin reports come back through the instance's binocle_host during the call. A
    // restart loses the figures of that frame and whatever the plugin had gathered.
    void evaluate(const binocle_eval_input &input);
    void finish();

private:
    SharedRegion shared_;
    std::string sentCalibration_, sentRig_; // texts the helper has already
    bool sentCalibrationNull_ = false, sentRigNull_ = false;
    uint64_t sentGeneration_ = 0;           // the helper that has them
};

// The helper's side: serves the plugin in `path` over socket `fd` until the host hangs
// up. Returns the process exit status.
int serveIsolatedPlugin(int fd, const std::string &path);

} // namespace binocle
