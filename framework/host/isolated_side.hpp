// SPDX-License-Identifier: MIT
// The isolated side's interface to a kind: the helper process serves one plugin
// instance, and each kind answers its own calls (kind_<name>.cpp). Internal to host/.
#pragma once

#include "host/ipc_messages.hpp"
#include "host/ipc_planes.hpp"
#include "host/ipc_wire.hpp"
#include "host/plugin_host.hpp"

#include <cstdint>
#include <memory>

namespace binocle {

// One plugin instance in the helper process, made by its kind's PluginKind::serve.
class ServedInstance {
public:
    virtual ~ServedInstance() = default;
    // Answers one call of the kind (op >= wire::kFirstKindOp): reads its request from
    // `r`, uses the host's shared region when the call has one, writes its reply's
    // payload to `out`. Throws PluginError (the plugin's refusal) or Error (a malformed
    // request).
    virtual void call(uint32_t op, wire::Reader &r, wire::Region region, wire::Writer &out) = 0;
};

// A served instance that answers its kind's calls with the kind's wrapper (Matcher,
// Source ...) made here, in the helper process; what the plugin logs goes to `sink`.
template <class Wrapper>
class ServedThrough : public ServedInstance {
public:
    ServedThrough(const PluginRecord &record, const ParamValues &params, HostSink sink) : instance_(record, params) {
        instance_.setSink(std::move(sink));
    }

protected:
    Wrapper instance_;
};

// PluginKind::serve for a served instance made as Served(record, params, sink).
template <class Served>
std::unique_ptr<ServedInstance> serveAs(const PluginRecord &record, const ParamValues &params, HostSink sink) {
    return std::make_unique<Served>(record, params, std::move(sink));
}

} // namespace binocle
