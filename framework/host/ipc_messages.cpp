// SPDX-License-Identifier: MIT
// The messages every kind shares: requests, create and describe, forwarded logs and
// figures, replies; each encoder next to its decoder.
#include "host/ipc_messages.hpp"

#include "host/plugin_kinds.hpp"

#include <cstddef>
#include <deque>
#include <memory>

namespace binocle::wire {

// ---- Requests -----------------------------------------------------------------------------------

void putParams(Writer &w, const ParamValues &params) {
    w.put<int32_t>(params.size());
    for (int32_t i = 0; i < params.size(); ++i) {
        const binocle_param &p = params.data()[i];
        w.str(p.name ? p.name : "").put<int32_t>(p.type).put<int64_t>(p.i).put<double>(p.d);
        w.cstr(p.s).put<int32_t>(p.explicit_);
    }
}

ParamValues getParams(Reader &r) {
    ParamValues values;
    const auto n = r.get<int32_t>();
    for (int32_t i = 0; i < n; ++i) {
        const std::string name = r.str();
        const auto type = r.get<int32_t>();
        const auto iv = r.get<int64_t>();
        const auto dv = r.get<double>();
        const auto [hasText, text] = r.cstr();
        const bool isExplicit = r.get<int32_t>() != 0;
        if (hasText) values.setText(name, type, text, isExplicit);
        else if (type == BINOCLE_PARAM_DOUBLE) values.setDouble(name, dv, isExplicit);
        else if (type == BINOCLE_PARAM_BOOL) values.setBool(name, iv != 0, isExplicit);
        else values.setInt(name, iv, isExplicit);
    }
    return values;
}

void putCreate(Writer &w, int32_t kind, const ParamValues &params) {
    w.put<int32_t>(kind);
    putParams(w, params);
}

std::pair<int32_t, ParamValues> getCreate(Reader &r) {
    const auto kind = r.get<int32_t>();
    return {kind, getParams(r)};
}

// ---- Messages -----------------------------------------------------------------------------------

std::string encodeReply(int32_t rc, const std::string &message, const std::string &payload) {
    Writer w;
    w.put<uint32_t>(kReply);
    put(w, ReplyHead{rc, message});
    return w.raw(payload).data();
}

void putDescription(Writer &w, const binocle_plugin_header &h, const std::vector<binocle_param_desc> &params) {
    w.put<uint32_t>(h.struct_size).put<uint32_t>(h.abi_version).put<uint32_t>(h.api_version).put<int32_t>(h.kind);
    w.cstr(h.name).cstr(h.version).cstr(h.description);
    w.put<int32_t>(static_cast<int32_t>(params.size()));
    for (const auto &d : params) {
        w.cstr(d.name).put<int32_t>(d.type).put<uint32_t>(d.flags).cstr(d.default_value);
        w.put<double>(d.min).put<double>(d.max).put<int64_t>(d.multiple_of);
        w.cstr(d.choices).cstr(d.unit).cstr(d.help);
    }
}

namespace {

// What a described record points into: its table (the kind's size, zeros but for the
// header and the settings), the texts and the settings table, owned.
struct Described {
    std::vector<std::max_align_t> table;
    binocle_plugin_header &header() { return *reinterpret_cast<binocle_plugin_header *>(table.data()); }
    std::vector<binocle_param_desc> params;
    std::deque<std::string> texts; // a deque: pointers into it stay valid as it grows
    const char *keep(const std::pair<bool, std::string> &t) {
        if (!t.first) return nullptr;
        texts.push_back(t.second);
        return texts.back().c_str();
    }
};

} // namespace

PluginRecord getDescription(Reader &r, const std::string &path) {
    auto d = std::make_shared<Described>();
    const auto structSize = r.get<uint32_t>();
    const auto abiVersion = r.get<uint32_t>();
    const auto apiVersion = r.get<uint32_t>();
    const PluginKind *kind = pluginKind(r.get<int32_t>());
    if (!kind) throw Error("malformed plugin kind from the plugin helper");
    d->table.assign((kind->tableSize + sizeof(std::max_align_t) - 1) / sizeof(std::max_align_t), std::max_align_t{});
    binocle_plugin_header &h = d->header();
    h.struct_size = structSize;
    h.abi_version = abiVersion;
    h.api_version = apiVersion;
    h.kind = kind->kind;
    h.name = d->keep(r.cstr());
    h.version = d->keep(r.cstr());
    h.description = d->keep(r.cstr());
    const auto count = r.get<int32_t>();
    if (count < 0 || count > 1000) throw Error("malformed settings table from the plugin helper");
    for (int32_t i = 0; i < count; ++i) {
        binocle_param_desc p{};
        p.name = d->keep(r.cstr());
        p.type = r.get<int32_t>();
        p.flags = r.get<uint32_t>();
        p.default_value = d->keep(r.cstr());
        p.min = r.get<double>();
        p.max = r.get<double>();
        p.multiple_of = r.get<int64_t>();
        p.choices = d->keep(r.cstr());
        p.unit = d->keep(r.cstr());
        p.help = d->keep(r.cstr());
        d->params.push_back(p);
    }
    kind->setParams(&h, d->params.empty() ? nullptr : d->params.data(), count);
    PluginRecord rec;
    rec.path = path;
    rec.name = h.name ? h.name : "";
    rec.version = h.version ? h.version : "";
    rec.description = h.description ? h.description : "";
    rec.kind = h.kind;
    rec.abi_version = h.abi_version;
    rec.api_version = h.api_version;
    rec.table = &h;
    rec.tableStorage = d;
    rec.described = true;
    return rec;
}

} // namespace binocle::wire
