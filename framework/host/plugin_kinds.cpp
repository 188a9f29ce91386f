// SPDX-License-Identifier: MIT
// The list of plugin kinds, and what every descriptor answers the same way.
#include "host/plugin_kinds.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <cstring>

namespace binocle {

// Every kind's descriptor, one per kind_<name>.cpp; the list is generated from those
// file names (framework/CMakeLists.txt), so a new kind edits no list.
std::vector<const PluginKind *> kindsByFile();

const std::vector<const PluginKind *> &pluginKinds() {
    static const std::vector<const PluginKind *> kinds = [] {
        std::vector<const PluginKind *> k = kindsByFile();
        std::sort(k.begin(), k.end(), [](const PluginKind *a, const PluginKind *b) { return a->kind < b->kind; });
        return k;
    }();
    return kinds;
}

const PluginKind *pluginKindNamed(const std::string &name) {
    for (const PluginKind *k : pluginKinds())
        if (name == k->name) return k;
    return nullptr;
}

const PluginKind *pluginKind(int32_t kind) {
    for (const PluginKind *k : pluginKinds())
        if (k->kind == kind) return k;
    return nullptr;
}

const PluginKind &requireKind(int32_t kind) {
    if (const PluginKind *k = pluginKind(kind)) return *k;
    throw Error("unknown plugin kind " + std::to_string(kind));
}

const char *kindName(int32_t kind) {
    const PluginKind *k = pluginKind(kind);
    return k ? k->name : "unknown";
}

size_t leastTableSize(int32_t kind, uint32_t api_version) {
    const PluginKind *k = pluginKind(kind);
    return k ? k->leastTableSize(api_version) : 0;
}

size_t PluginKind::leastTableSize(uint32_t api_version) const {
    for (const auto &v : versions)
        if (v.api_version == api_version) return v.least;
    return 0;
}

namespace {

template <class T>
T at(const binocle_plugin_header *table, size_t offset) {
    T v{};
    std::memcpy(&v, reinterpret_cast<const char *>(table) + offset, sizeof v);
    return v;
}

} // namespace

std::vector<std::string> PluginKind::missingEntries(const binocle_plugin_header *table) const {
    std::vector<std::string> missing;
    for (const auto &e : entries)
        if (e.mandatory && !at<void (*)()>(table, e.offset)) missing.emplace_back(e.name);
    return missing;
}

std::pair<const binocle_param_desc *, int32_t> PluginKind::rawParams(const binocle_plugin_header *table) const {
    return {at<const binocle_param_desc *>(table, paramsOffset), at<int32_t>(table, paramCountOffset)};
}

std::vector<binocle_param_desc> PluginKind::params(const binocle_plugin_header *table) const {
    const auto [params, count] = rawParams(table);
    if (!params || count <= 0) return {};
    return {params, params + count};
}

void PluginKind::setParams(binocle_plugin_header *table, const binocle_param_desc *params, int32_t count) const {
    std::memcpy(reinterpret_cast<char *>(table) + paramsOffset, &params, sizeof params);
    std::memcpy(reinterpret_cast<char *>(table) + paramCountOffset, &count, sizeof count);
}

const char *PluginKind::callName(uint32_t op) const {
    for (const auto &e : entries)
        if (e.op == op) return e.name;
    return "call";
}

} // namespace binocle
