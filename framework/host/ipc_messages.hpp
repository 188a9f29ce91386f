// SPDX-License-Identifier: MIT
// The messages every kind shares between Binocle and its helper process: the requests'
// head, create and describe, the logs, figures and texts the helper process forwards,
// and the reply that ends a call. A kind's own calls and payloads are the kind's
// (kind_<name>_messages.hpp). Internal to host/.
#pragma once

#include "host/ipc_wire.hpp"
#include "host/plugin_record.hpp"
#include "host/plugin_settings.hpp"

#include <binocle/abi.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace binocle::wire {

// Operations every kind has; a kind's own calls are numbered from kFirstKindOp in its
// descriptor (host/plugin_kinds.hpp), so that a new kind adds no number here.
enum Op : uint32_t {
    kDescribe = 1, // the plugin's header and settings table, without creating an instance
    kCreate = 2,
    kDestroy = 3,
    kFirstKindOp = 16,
};

// A shared memory region of the host, by number; kNoRegion when the request uses none.
// When the request carries a file descriptor, it is that region's (new) file.
constexpr uint32_t kNoRegion = 0xffffffffu;

// What every request starts with; the operation's own fields follow.
struct RequestHead {
    uint32_t op = 0;
    uint32_t region = kNoRegion;
    uint64_t region_bytes = 0;
};
constexpr auto wireFields(const RequestHead *) { return std::make_tuple(&RequestHead::op, &RequestHead::region, &RequestHead::region_bytes); }

// kCreate: the kind the host expects and the settings.
void putCreate(Writer &w, int32_t kind, const ParamValues &params);
std::pair<int32_t, ParamValues> getCreate(Reader &r);

void putParams(Writer &w, const ParamValues &params);
ParamValues getParams(Reader &r);

// Any number of logs, figures and texts may come before the reply that ends a call.
enum Message : uint32_t { kReply = 1, kLog, kMetric, kText };

// Who wrote a forwarded log line.
enum LogOrigin : uint8_t {
    kFromPlugin = 0, // binocle_host.log: tagged "[plugin] ..." by the host
    kFromOutput = 1, // the plugin wrote to its stdout / stderr: tagged as well
    kFromHelper = 2, // the helper process's own words (they name the plugin already)
};

// Each message: its type, then its fields; read with get<LogMessage>(r) etc. after the
// type (kLog, kMetric, kText) was read.
struct LogMessage {
    static constexpr uint32_t type = kLog;
    uint8_t origin = kFromPlugin;
    int32_t level = 0;
    std::string text;
};
constexpr auto wireFields(const LogMessage *) { return std::make_tuple(&LogMessage::origin, &LogMessage::level, &LogMessage::text); }
struct MetricMessage {
    static constexpr uint32_t type = kMetric;
    std::string name;
    double value = 0;
    std::string unit;
};
constexpr auto wireFields(const MetricMessage *) { return std::make_tuple(&MetricMessage::name, &MetricMessage::value, &MetricMessage::unit); }
struct TextMessage {
    static constexpr uint32_t type = kText;
    std::string name, text;
};
constexpr auto wireFields(const TextMessage *) { return std::make_tuple(&TextMessage::name, &TextMessage::text); }
template <class M>
std::string encode(const M &m) {
    Writer w;
    w.put<uint32_t>(M::type);
    put(w, m);
    return w.data();
}

// The end of a call: the result code, the plugin's message, then the call's own payload.
std::string encodeReply(int32_t rc, const std::string &message, const std::string &payload);
// After kReply was read, get<ReplyHead>(r) leaves the Reader at the payload.
struct ReplyHead {
    int32_t rc = 0;
    std::string message;
};
constexpr auto wireFields(const ReplyHead *) { return std::make_tuple(&ReplyHead::rc, &ReplyHead::message); }

// kDescribe's reply: a plugin header and settings table, by value.
void putDescription(Writer &w, const binocle_plugin_header &h, const std::vector<binocle_param_desc> &params);
// A record that owns copies of the header's texts and of the settings table; no library.
PluginRecord getDescription(Reader &r, const std::string &path);

} // namespace binocle::wire
