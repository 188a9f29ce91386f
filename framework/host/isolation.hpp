// SPDX-License-Identifier: MIT
// Plugins out of process (libcamera's IPA isolation is the model): files examined in
// short-lived children, and instances of any kind run in a helper process
// (binocle-plugin-helper) behind a proxy. Words: the *helper process* runs the plugin;
// the *proxy* (PluginProxy) is its host-side end; the *codec* (ipc_*.hpp, kind_*_messages.hpp)
// encodes what crosses; the *isolated side* (isolated_side.cpp) serves the calls.
#pragma once

#include "host/ipc_messages.hpp"
#include "host/ipc_planes.hpp"
#include "host/ipc_wire.hpp"
#include "host/plugin_host.hpp"

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <sys/types.h>
#include <vector>

namespace binocle {

struct PluginKind;

// Opens each file in a child process of its own (at most a few at once); returns the
// reason for each file that failed there: refused by the checks, crashed (the signal), or
// still loading after timeout_ms (killed). Files absent from the map loaded fine.
std::map<std::string, std::string> examineInChildren(const std::vector<std::string> &paths, int32_t timeout_ms);

// The helper executable: $BINOCLE_PLUGIN_HELPER, else <prefix>/libexec/binocle/
// binocle-plugin-helper (host/install_prefix.hpp: the prefix a program named, else the
// running executable's). Throws Error when absent.
std::string helperExecutable();

// A plugin file's header and settings table, read by a helper process: none of the
// file's code runs in this one (its library constructors included). Throws Error with the
// reason when the helper process refuses the file, crashes on it (the signal) or is still
// loading it after timeout_ms (killed). The record has no library (`described`).
PluginRecord describeInHelper(const std::string &path, int32_t timeout_ms);

// `n` rounded up to whole pages.
size_t pageAligned(size_t n);

// A shared memory file (memfd) mapped in this process; the helper process maps the same file.
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
    wire::Region region() const { return {data(), bytes_}; }
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

// The host's end of a plugin instance that lives in a helper process: spawns
// binocle-plugin-helper, creates the instance there, makes each call with a watchdog
// (call_timeout_ms), and forwards what the plugin logs and reports to the instance's
// binocle_host, so that its messages read "[plugin] ..." as in process. Pixels cross in
// SharedRegions, never through the socket. A crash or a call past its watchdog throws
// PluginError naming the plugin, the call and the signal, or, with `restart`, restarts
// the helper process (create again) and the call's result is lost (counted).
class PluginProxy {
public:
    virtual ~PluginProxy();
    PluginProxy(const PluginProxy &) = delete;
    PluginProxy &operator=(const PluginProxy &) = delete;
    int32_t proxyRestarts() const { return restarts_; }
    // Calls whose result was lost to a crash or a hang that a restart survived.
    int64_t proxyLostCalls() const { return lost_; }
    pid_t pid() const { return pid_; }

protected:
    // A restart's cost is the kind's (PluginKind::lostOnRestart).
    PluginProxy(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation,
                const binocle_host *host);
    struct Reply {
        int32_t rc = 0;
        std::string message;
        wire::Reader payload;
    };
    // Spawns the helper process and creates the instance; throws PluginError.
    void launch();
    // One request; the region's file goes along when this helper process has not mapped
    // it yet. timeout_ms < 0: call_timeout_ms; otherwise `limit` says where timeout_ms
    // comes from. A reply other than BINOCLE_OK throws PluginError with the plugin's
    // message. Throws (internally) when the helper process died or was killed.
    Reply call(uint32_t op, const std::string &payload = {}, SharedRegion *region = nullptr, int32_t timeout_ms = -1,
               const char *limit = nullptr);
    // Runs `attempt`; true when it completed. When the helper process dies during it:
    // with `restart` and restarts left, restarts it and returns false (the result is
    // lost); otherwise throws PluginError.
    bool guarded(const std::function<void()> &attempt);
    // Runs `attempt` until it completes (restarts permitting).
    void retried(const std::function<void()> &attempt) {
        while (!guarded(attempt)) {
        }
    }
    // After a restart has created the instance anew (a source starts again).
    virtual void afterRestart() {}
    const PluginRecord &proxiedRecord() const { return record_; }
    const IsolationOptions &options() const { return options_; }
    uint64_t generation() const { return generation_; }
    // Turns a failure to start (launch) into a PluginError; for constructors.
    void launchOrThrow();
    friend PluginRecord describeInHelper(const std::string &path, int32_t timeout_ms);

private:
    void spawn();
    void stopHelper();
    const char *callName(uint32_t op) const;
    Reply exchange(const std::string &who, const std::string &request, int fd, int32_t timeout_ms,
                   const std::string &limit);
    void dispatch(uint32_t type, wire::Reader &message);
    // Restarts after `gone` while the rig allows; throws PluginError when it does not.
    void recover(const std::string &gone);

    PluginRecord record_;
    ParamValues params_;
    IsolationOptions options_;
    const binocle_host *host_;
    const PluginKind *kind_; // nullptr while describing a file
    pid_t pid_ = -1;
    int socket_ = -1;
    uint64_t generation_ = 0; // one per helper process started
    int32_t restarts_ = 0;
    int64_t lost_ = 0;
    std::string gone_; // why the helper process is gone, for calls after a crash
};

// A kind's interface (Impl) implemented by a proxy: the instance lives in a helper
// process, started when this object is made.
template <class Impl>
class Proxied : public Impl, protected PluginProxy {
public:
    Proxied(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation,
            const std::shared_ptr<binocle_host> &host)
        : PluginProxy(record, params, isolation, host.get()) {
        launchOrThrow();
    }
    bool isolated() const override { return true; }
    int32_t restarts() const override { return proxyRestarts(); }
    int64_t lostCalls() const override { return proxyLostCalls(); }
};

// The isolated side: serves the plugin in `path` over socket `fd` until the host hangs
// up. Returns the process exit status.
int serveIsolatedPlugin(int fd, const std::string &path);

} // namespace binocle
