// SPDX-License-Identifier: MIT
// The wire codec of `isolation: process`: every message between Binocle and its helper
// process, each encoded and decoded here and nowhere else (libcamera's generated IPA
// serialisers are the model: one description, so encode and decode cannot drift).
// Internal to host/. Transport: one message per request on a SOCK_SEQPACKET socket,
// shared memory files (memfd) passed with SCM_RIGHTS; pixels and arrays cross in those
// files, described by offsets, never through the socket.
#pragma once

#include "core/error.hpp"
#include "host/plugin_host.hpp"

#include <binocle/abi.h>

#include <cstdint>
#include <cstring>
#include <deque>
#include <string>
#include <utility>
#include <tuple>
#include <type_traits>
#include <vector>

namespace binocle::wire {

// ---- Primitive encoding ---------------------------------------------------------------------

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
    // One field of a message described by its fields (below): a number or a text.
    template <class T>
    Writer &field(const T &v) {
        if constexpr (std::is_same_v<T, std::string>) return str(v);
        else return put<T>(v);
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
    template <class T>
    void field(T &v) {
        if constexpr (std::is_same_v<T, std::string>) v = str();
        else v = get<T>();
    }
    bool atEnd() const { return at_ == data_.size(); }

private:
    void need(uint64_t n) const {
        if (n > data_.size() - at_) throw Error("malformed message between Binocle and its plugin helper");
    }
    std::vector<char> data_;
    size_t at_ = 0;
};

// ---- Transport --------------------------------------------------------------------------------

// Sends one message (in chunks when it is large), with a file descriptor attached when
// fd >= 0. False when the peer is gone (no SIGPIPE). Callers on several threads of one
// process serialise their sends.
bool sendMessage(int sock, const std::string &msg, int fd = -1);
// Receives one message; *fd is -1 when none came along (fd may be NULL). False at end of
// stream or on a malformed message.
bool receiveMessage(int sock, std::string &msg, int *fd);

// ---- Requests (host -> helper process) ----------------------------------------------------

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

// Messages of fixed fields are described once, by the list of their fields in wire order:
// `wireFields(const M *)` returns their member pointers (for an ABI struct, its scalar
// fields; its arrays follow). put() and get() both walk that list, so encoding and
// decoding cannot drift.
// The scalar fields of the ABI's images and clouds; their arrays follow (putImage, putCloud).
constexpr auto wireFields(const binocle_image *) {
    return std::make_tuple(&binocle_image::width, &binocle_image::height, &binocle_image::stride_bytes, &binocle_image::format);
}
constexpr auto wireFields(const binocle_cloud *) {
    return std::make_tuple(&binocle_cloud::count, &binocle_cloud::image_width, &binocle_cloud::image_height, &binocle_cloud::frame);
}
template <class M>
void put(Writer &w, const M &m) {
    std::apply([&](auto... f) { (w.field(m.*f), ...); }, wireFields(&m));
}
template <class M>
M get(Reader &r) {
    M m{};
    std::apply([&](auto... f) { (r.field(m.*f), ...); }, wireFields(&m));
    return m;
}

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

// ---- Messages (helper process -> host) -----------------------------------------------------

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

// ---- Planes in shared memory --------------------------------------------------------------

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

// A shared region as the reader sees it: decoded planes are checked to lie within it.
struct Region {
    uint8_t *base = nullptr;
    uint64_t bytes = 0;
};

void putImage(Writer &w, const binocle_image &placed);
// The image at its offset in the region, checked to lie within it.
binocle_image getImage(Reader &r, Region region);
// The array at an offset of the region, checked to lie within it.
uint8_t *arrayAt(uint64_t offset, uint64_t length, Region region);

// Named planes (a frame's extras, a matcher's extras) placed in a Layout: their count,
// then each one's name and image.
void putNamedImages(Writer &w, Layout &layout, const binocle_named_image *images, int32_t count);
// Decoded: the images point into the region, the names into `names`.
struct NamedImages {
    std::vector<binocle_named_image> images;
    std::deque<std::string> names; // a deque: pointers into it stay valid as it grows
};
void getNamedImages(Reader &r, Region region, NamedImages &out);

// A frame whose planes are placed in a Layout.
void putFrame(Writer &w, Layout &layout, const binocle_stereo_frame &f);
// What a decoded frame points into besides the region: extra planes, metadata.
struct FrameTexts {
    NamedImages extras;
    std::string metadata;
};
binocle_stereo_frame getFrame(Reader &r, Region region, FrameTexts &texts);

// A cloud whose arrays are placed in a Layout.
void putCloud(Writer &w, Layout &layout, const binocle_cloud &c);
binocle_cloud getCloud(Reader &r, Region region);

// ---- The kinds' calls ----------------------------------------------------------------------

// Matcher compute: left and right at 0 and image_bytes, the disparity (CV_32F) at
// 2 * image_bytes; images tightly packed. The matcher's extras go after the disparity
// (at its page-aligned end), within extras_bytes; the reply describes them
// (putNamedImages, offsets from there).
struct ComputeRequest {
    int32_t width = 0, height = 0, cv_type = 0;
    uint64_t image_bytes = 0;
    uint64_t extras_bytes = 0;
};
constexpr auto wireFields(const ComputeRequest *) {
    return std::make_tuple(&ComputeRequest::width, &ComputeRequest::height, &ComputeRequest::cv_type,
                           &ComputeRequest::image_bytes, &ComputeRequest::extras_bytes);
}

// Matcher disparity_range's reply.
void putRange(Writer &w, std::pair<int32_t, int32_t> range);
std::pair<int32_t, int32_t> getRange(Reader &r);

// Source grab: the request's wait; the reply's bytes needed, then (when they fit the
// region) the frame.
void putGrabRequest(Writer &w, int32_t timeout_ms);
int32_t getGrabRequest(Reader &r);

// Transform apply's reply: the cloud's count and frame, and where its arrays are now.
struct AppliedCloud {
    int64_t count = 0;
    int32_t frame = 0;
    uint64_t xyz = 0, rgb = 0, pixel = 0;
};
constexpr auto wireFields(const AppliedCloud *) {
    return std::make_tuple(&AppliedCloud::count, &AppliedCloud::frame, &AppliedCloud::xyz, &AppliedCloud::rgb, &AppliedCloud::pixel);
}

// Evaluator evaluate: the input's planes in a Layout. The calibration and rig texts,
// which change rarely, are sent only when `sendTexts` (else the helper process keeps
// the last ones it got).
struct EvaluateTexts {
    std::pair<bool, std::string> calibration{false, ""}, rig{false, ""};
};
void putEvaluate(Writer &w, Layout &layout, const binocle_eval_input &in, bool sendCalibration, bool sendRig);
// What a decoded input points into; `texts` keeps the texts last sent.
struct EvaluateInput {
    binocle_eval_input in{};
    binocle_stereo_frame frame{};
    FrameTexts frameTexts;
    NamedImages disparityExtras;
    binocle_image images[3]{};
    binocle_cloud cloud{};
    std::pair<bool, std::string> output{false, ""};
};
void getEvaluate(Reader &r, Region region, EvaluateTexts &texts, EvaluateInput &out);

} // namespace binocle::wire
