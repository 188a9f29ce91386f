// SPDX-License-Identifier: MIT
// The messages between Binocle and binocle-plugin-helper (`isolation: process`): one
// request per call on a SOCK_SEQPACKET socket, shared memory files (memfd) passed with
// SCM_RIGHTS, and the helper's replies, logs and figures. Internal to host/.
#pragma once

#include "core/error.hpp"
#include "host/plugin_host.hpp"

#include <binocle/abi.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace binocle::helper {

// Requests, host -> helper. Every request starts with RequestHead.
enum Op : uint32_t {
    kDescribe = 1, // the plugin's header and settings table, without creating an instance
    kCreate,
    kDestroy,
    kCompute, // matcher
    kRange,
    kStart, // source
    kStop,
    kGrab,
    kCalibration,
    kStatistics,
    kApply,    // transform
    kEvaluate, // evaluator
    kFinish,
};

// Messages, helper -> host. Any number of logs, figures and texts may come before the
// reply that ends a call.
enum Message : uint32_t { kReply = 1, kLog, kMetric, kText };

// Who wrote a forwarded log line.
enum LogOrigin : uint8_t {
    kFromPlugin = 0, // binocle_host.log: tagged "[plugin] ..." by the host
    kFromOutput = 1, // the plugin wrote to its stdout / stderr: tagged as well
    kFromHelper = 2, // the helper's own words (they name the plugin already)
};

// A shared memory region of the host, by number; kNoRegion when the request uses none.
// When the request carries a file descriptor, it is that region's (new) file.
constexpr uint32_t kNoRegion = 0xffffffffu;
struct RequestHead {
    uint32_t op;
    uint32_t region;
    uint64_t region_bytes;
};

class Writer {
public:
    template <class T>
    Writer &put(T v) {
        buf_.append(reinterpret_cast<const char *>(&v), sizeof v);
        return *this;
    }
    Writer &str(const std::string &s) {
        put<uint64_t>(s.size());
        buf_ += s;
        return *this;
    }
    // NULL and "" differ for the ABI: a presence byte, then the text.
    Writer &cstr(const char *s) {
        put<uint8_t>(s != nullptr);
        return str(s ? s : "");
    }
    Writer &raw(const std::string &bytes) {
        buf_ += bytes;
        return *this;
    }
    const std::string &data() const { return buf_; }

private:
    std::string buf_;
};

class Reader {
public:
    // A vector, not a string: GCC 12 warns falsely about a short string's inline buffer.
    explicit Reader(const std::string &data = {}) : data_(data.begin(), data.end()) {}
    template <class T>
    T get() {
        T v{};
        need(sizeof v);
        std::memcpy(&v, data_.data() + at_, sizeof v);
        at_ += sizeof v;
        return v;
    }
    std::string str() {
        const auto n = get<uint64_t>();
        need(n);
        std::string s(data_.data() + at_, n);
        at_ += n;
        return s;
    }
    // A text that may be NULL (Writer::cstr): presence and text.
    std::pair<bool, std::string> cstr() {
        const bool present = get<uint8_t>() != 0;
        return {present, str()};
    }

private:
    void need(uint64_t n) const {
        if (n > data_.size() - at_) throw Error("malformed message between Binocle and its plugin helper");
    }
    std::vector<char> data_;
    size_t at_ = 0;
};

// Sends one message (in chunks when it is large), with a file descriptor attached when
// fd >= 0. False when the peer is gone (no SIGPIPE). Callers on several threads of one
// process serialise their sends.
bool sendMessage(int sock, const std::string &msg, int fd = -1);
// Receives one message; *fd is -1 when none came along (fd may be NULL). False at end of
// stream or on a malformed message.
bool receiveMessage(int sock, std::string &msg, int *fd);

std::string encodeParams(const ParamValues &params);
ParamValues decodeParams(Reader &r);

// A settings table and a plugin header, by value.
void encodeDescription(Writer &w, const binocle_plugin_header &h, const std::vector<binocle_param_desc> &params);
// A record that owns copies of the header's texts and of the settings table; no library.
PluginRecord decodeDescription(Reader &r, const std::string &path);

// Images and arrays laid out one after another in a shared region: each plane gets an
// offset (64-byte aligned) and tightly packed rows.
class Layout {
public:
    // Where `im` goes; an image already placed (same pixels, same description) is placed
    // once. Returns the description of the copy: data is the offset, as an integer.
    binocle_image place(const binocle_image &im);
    // `bytes` of an array; returns its offset.
    uint64_t placeArray(const void *data, uint64_t bytes);
    uint64_t bytes() const { return end_; }
    // Copies every placed plane into `base` (bytes() of it).
    void copyInto(uint8_t *base) const;

private:
    struct Item {
        const void *src;
        uint64_t offset;
        binocle_image image; // as given (source stride), for images
        uint64_t bytes;      // in the region
        bool isImage;
    };
    uint64_t take(uint64_t bytes);
    std::vector<Item> items_;
    uint64_t end_ = 0;
};

void putImage(Writer &w, const binocle_image &placed);
// The image at its offset in `base`, checked to lie within `bytes`.
binocle_image getImage(Reader &r, uint8_t *base, uint64_t bytes);
// The array at an offset of `base`, checked to lie within `bytes` (nullptr when absent).
uint8_t *arrayAt(uint64_t offset, uint64_t length, uint8_t *base, uint64_t bytes);

} // namespace binocle::helper
