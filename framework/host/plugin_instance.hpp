// SPDX-License-Identifier: MIT
// What every plugin instance has, whatever its kind: where its logs and figures go
// (HostSink), how it runs (IsolationOptions: in this process or in a helper process of
// its own, host/isolation.hpp), and the common part of the kinds' wrappers
// (PluginInstanceBase), which makes that choice once, when the instance is made.
#pragma once

#include "host/plugin_record.hpp"
#include "host/plugin_settings.hpp"

#include <binocle/abi.h>

#include <functional>
#include <memory>
#include <string>

namespace binocle {

// How a rig runs a plugin: in the process (default), or in a helper process of its own
// (`isolation: process` in the rig block) that may crash or hang without taking Binocle
// down; every kind of plugin honours it. Given to the instance beside its settings.
struct IsolationOptions {
    bool process = false;
    int32_t call_timeout_ms = 0; // 0: no watchdog
    bool restart = false;        // restart a helper that crashed or hung
    int32_t max_restarts = 3;
};

// Where figures and logs reported by a plugin instance go.
struct HostSink {
    std::function<void(int32_t level, const std::string &)> log;
    std::function<void(const std::string &name, double value, const std::string &unit)> metric;
    std::function<void(const std::string &name, const std::string &text)> text;
};

// How an instance runs: in this process, or behind a proxy that talks to its helper
// process (host/isolation.hpp). Chosen once, when the instance is made; each kind's
// wrapper holds one implementation of its kind's interface (kind_<name>.cpp).
class InstanceImpl {
public:
    virtual ~InstanceImpl() = default;
    virtual bool isolated() const { return false; }
    virtual int32_t restarts() const { return 0; }
    virtual int64_t lostCalls() const { return 0; }
};

// Common part of the instance wrappers (kind_<name>.hpp).
class PluginInstanceBase {
public:
    // One wrapper per plugin instance: a copy would destroy the instance twice.
    PluginInstanceBase(const PluginInstanceBase &) = delete;
    PluginInstanceBase &operator=(const PluginInstanceBase &) = delete;
    const PluginRecord &record() const { return record_; }
    // Replaces where this instance's metrics and logs go (default: log to stderr).
    void setSink(HostSink sink);
    // True when the plugin runs in a helper process (`isolation: process`).
    bool isolated() const { return running_ && running_->isolated(); }
    // Restarts of its helper process, and calls whose result they lost (0 in process).
    int32_t restarts() const { return running_ ? running_->restarts() : 0; }
    int64_t lostCalls() const { return running_ ? running_->lostCalls() : 0; }

protected:
    explicit PluginInstanceBase(const PluginRecord &record);
    // Instances of a described record run isolated whatever the rig says.
    static bool runsIsolated(const PluginRecord &record, const IsolationOptions &isolation);
    // The implementation for this instance: InProcess(record, params, host) or, when it
    // runs isolated, Proxy(record, params, isolation, host). The one place the choice is made.
    template <class Impl, class InProcess, class Proxy>
    std::unique_ptr<Impl> choose(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation) {
        std::unique_ptr<Impl> impl;
        if (runsIsolated(record, isolation)) impl = std::make_unique<Proxy>(record, params, isolation, host_);
        else impl = std::make_unique<InProcess>(record, params, host_);
        running_ = impl.get();
        return impl;
    }
    PluginRecord record_;
    std::shared_ptr<binocle_host> host_; // deleted with its sink context
    const InstanceImpl *running_ = nullptr; // the derived wrapper's implementation
};

} // namespace binocle
