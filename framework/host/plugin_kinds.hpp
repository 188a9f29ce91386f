// SPDX-License-Identifier: MIT
// One descriptor per plugin kind: its name, its key in a rig file, the least table size
// per API version, its entries (mandatory or not) and the calls an isolated instance
// makes. Loading, the table checks, the helper process, conformance and the messages all
// read a kind's rules here; a kind's own file (kind_<name>.cpp) defines its descriptor.
#pragma once

#include "host/plugin_host.hpp"

#include <binocle/abi.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace binocle {

class ServedInstance; // host/isolated_side.hpp

// End of a table entry: offsetof + sizeof. An entry's offset never changes once an API
// version has shipped (tables only grow at their end), so these values are frozen.
#define BINOCLE_END_OF(type, member) (offsetof(type, member) + sizeof(static_cast<type *>(nullptr)->member))

struct PluginKind {
    // The least table a plugin of an API version must declare: up to its last entry.
    struct TableVersion {
        uint32_t api_version;
        size_t least;     // end of the last entry of that API version
        const char *last; // name of that entry, for messages
    };
    // An entry of the table that is a function.
    struct Entry {
        const char *name;      // "compute", as in the ABI header
        size_t offset;         // in the table
        bool mandatory;        // a table leaving it NULL is refused at load
        uint32_t op;           // its request to an isolated instance (0: none)
    };
    using Serve = std::unique_ptr<ServedInstance> (*)(const PluginRecord &, const ParamValues &, HostSink);

    int32_t kind = 0;           // BINOCLE_KIND_*
    const char *name = "";      // "matcher": messages, `binocle plugins`, conformance
    const char *rigKey = "";    // its key in a rig file: "matcher", "transforms"
    // How a rig file holds blocks of this kind under rigKey: exactly one (a rig without
    // it is refused), at most one, or a list. Config reads every kind's blocks this way.
    enum class InRig { One, Optional, List };
    InRig inRig = InRig::One;
    size_t tableSize = 0;       // the kind's table as this host knows it (its API version)
    size_t paramsOffset = 0;    // where `params` and `param_count` sit in the table
    size_t paramCountOffset = 0;
    std::vector<TableVersion> versions; // one row per API version; new versions add rows
    std::vector<Entry> entries;
    const char *lostOnRestart = ""; // what a restart of its helper process costs a run
    Serve serve = nullptr;          // the instance in the helper process (isolated side)

    // 0 for an API version this kind does not know.
    size_t leastTableSize(uint32_t api_version) const;
    // Names of the mandatory entries that `table` leaves NULL.
    std::vector<std::string> missingEntries(const binocle_plugin_header *table) const;
    // The settings table of a table of this kind, as declared (the count may be garbage).
    std::pair<const binocle_param_desc *, int32_t> rawParams(const binocle_plugin_header *table) const;
    // The same, copied; empty when there is none.
    std::vector<binocle_param_desc> params(const binocle_plugin_header *table) const;
    // Points the table's settings table at `params` (a described record's copy).
    void setParams(binocle_plugin_header *table, const binocle_param_desc *params, int32_t count) const;
    // The entry an isolated call makes ("compute"), for messages; "call" when unknown.
    const char *callName(uint32_t op) const;
};

// A kind's descriptor: what every kind's table has (the header, its settings table, and
// create, destroy and last_error, mandatory), then the kind's own API versions and calls
// (`calls`, appended to the entries), what a restart of its helper process costs a run
// and its instance in the helper process.
template <class Table>
PluginKind tableKind(int32_t kind, const char *name, const char *rigKey, PluginKind::InRig inRig,
                     std::vector<PluginKind::TableVersion> versions, const std::vector<PluginKind::Entry> &calls,
                     const char *lostOnRestart, PluginKind::Serve serve) {
    PluginKind k;
    k.kind = kind;
    k.name = name;
    k.rigKey = rigKey;
    k.inRig = inRig;
    k.tableSize = sizeof(Table);
    k.paramsOffset = offsetof(Table, params);
    k.paramCountOffset = offsetof(Table, param_count);
    k.versions = std::move(versions);
    k.entries = {{"create", offsetof(Table, create), true, 0},
                 {"destroy", offsetof(Table, destroy), true, 0},
                 {"last_error", offsetof(Table, last_error), true, 0}};
    k.entries.insert(k.entries.end(), calls.begin(), calls.end());
    k.lostOnRestart = lostOnRestart;
    k.serve = serve;
    return k;
}

// Every kind this host knows, in BINOCLE_KIND_* order.
const std::vector<const PluginKind *> &pluginKinds();
// nullptr for a kind this host does not know.
const PluginKind *pluginKind(int32_t kind);
// The kind of that name ("matcher"); nullptr when there is none.
const PluginKind *pluginKindNamed(const std::string &name);
// The kind's descriptor; throws Error for an unknown kind.
const PluginKind &requireKind(int32_t kind);

} // namespace binocle
