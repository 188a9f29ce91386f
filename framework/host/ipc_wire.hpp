// SPDX-License-Identifier: MIT
// The wire primitives of `isolation: process` (libcamera's IPC serialisers are the
// model): Writer and Reader, and messages of fixed fields described once by the list of
// their fields (`wireFields`), so that encoding and decoding cannot drift. Internal to
// host/. Above them: the transport (ipc_transport.hpp), the messages every kind shares
// (ipc_messages.hpp), planes in shared memory (ipc_planes.hpp) and each kind's own
// payloads (kind_<name>_messages.hpp).
#pragma once

#include "core/error.hpp"

#include <binocle/abi.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace binocle::wire {

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

} // namespace binocle::wire
