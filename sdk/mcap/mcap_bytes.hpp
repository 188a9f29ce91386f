// SPDX-License-Identifier: MIT
// The byte layer of MCAP (internal to libbinocle_mcap): little-endian fields appended to a
// buffer, a bounds-checked cursor over untrusted bytes, and chunk (de)compression.
#pragma once

#include <binocle/mcap.hpp>
#include <binocle/text.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace binocle::mcap::detail {

// ---- Writing -----------------------------------------------------------------------------

struct Bytes {
    std::vector<uint8_t> b;

    void u8(uint8_t v) { b.push_back(v); }
    template <typename T> void le(T v) {
        uint8_t tmp[sizeof(T)];
        for (size_t i = 0; i < sizeof(T); ++i) tmp[i] = static_cast<uint8_t>(static_cast<uint64_t>(v) >> (8 * i));
        b.insert(b.end(), tmp, tmp + sizeof(T));
    }
    void u16(uint16_t v) { le(v); }
    void u32(uint32_t v) { le(v); }
    void u64(uint64_t v) { le(v); }
    void raw(const void *p, size_t n) {
        const auto *c = static_cast<const uint8_t *>(p);
        b.insert(b.end(), c, c + n);
    }
    void str(const std::string &s) {
        u32(static_cast<uint32_t>(s.size()));
        raw(s.data(), s.size());
    }
    // Fields with their size in bytes before them (4 bytes), written by `fill`.
    template <class Fill>
    void sized32(Fill fill) {
        const size_t at = b.size();
        u32(0);
        fill();
        patch32(at, static_cast<uint32_t>(b.size() - at - 4));
    }
    void map(const KeyValues &kv) {
        sized32([&] {
            for (const auto &[k, v] : kv) {
                str(k);
                str(v);
            }
        });
    }
    // Channel ids, each with a number: Statistics' message counts, Chunk Index's offsets.
    template <class Pairs>
    void channelMap(const Pairs &pairs) {
        sized32([&] {
            for (const auto &[channel, n] : pairs) {
                u16(channel);
                u64(n);
            }
        });
    }
    void patch32(size_t at, uint32_t v) {
        for (int i = 0; i < 4; ++i) b[at + i] = static_cast<uint8_t>(v >> (8 * i));
    }
    void patch64(size_t at, uint64_t v) {
        for (int i = 0; i < 8; ++i) b[at + i] = static_cast<uint8_t>(v >> (8 * i));
    }
    // Opens a record: opcode and a length patched by end().
    size_t begin(Opcode op) {
        u8(static_cast<uint8_t>(op));
        const size_t at = b.size();
        u64(0);
        return at;
    }
    void end(size_t at) { patch64(at, b.size() - at - 8); }
};

// ---- Reading -----------------------------------------------------------------------------

// Reads the fields of one record; a read past its end throws, naming `where` (file and
// record offset) and the field.
class Cursor {
public:
    Cursor(const uint8_t *data, size_t size, std::string where) : p_(data), n_(size), where_(std::move(where)) {}

    size_t left() const { return n_ - i_; }
    size_t pos() const { return i_; }
    const uint8_t *here() const { return p_ + i_; }

    [[noreturn]] void fail(const std::string &what) const { throw Error(where_ + ": " + what); }

    void need(size_t k, const char *field) const {
        if (k > left())
            fail(std::string(field) + ": needs " + std::to_string(k) + " bytes but the record has " +
                 std::to_string(left()) + " left");
    }
    template <typename T> T le(const char *field) {
        need(sizeof(T), field);
        uint64_t v = 0;
        for (size_t k = 0; k < sizeof(T); ++k) v |= static_cast<uint64_t>(p_[i_ + k]) << (8 * k);
        i_ += sizeof(T);
        return static_cast<T>(v);
    }
    uint8_t u8(const char *f) { return le<uint8_t>(f); }
    uint16_t u16(const char *f) { return le<uint16_t>(f); }
    uint32_t u32(const char *f) { return le<uint32_t>(f); }
    uint64_t u64(const char *f) { return le<uint64_t>(f); }
    std::string str(const char *field) {
        const uint32_t len = u32(field);
        need(len, field);
        std::string s(reinterpret_cast<const char *>(p_ + i_), len);
        i_ += len;
        return s;
    }
    // A byte run with a length prefix of 4 or 8 bytes; returns its start, advances past it.
    const uint8_t *run(uint64_t len, const char *field) {
        if (len > left())
            fail(std::string(field) + " claims " + std::to_string(len) + " bytes but the record has " +
                 std::to_string(left()) + " left");
        const uint8_t *at = p_ + i_;
        i_ += static_cast<size_t>(len);
        return at;
    }
    KeyValues map(const char *field) {
        const uint32_t len = u32(field);
        Cursor inner(run(len, field), len, where_ + " (" + field + ")");
        KeyValues out;
        while (inner.left() > 0) {
            std::string k = inner.str("key");
            std::string v = inner.str("value");
            out.emplace_back(std::move(k), std::move(v));
        }
        return out;
    }
    void skip(size_t k, const char *field) { run(k, field); }

private:
    const uint8_t *p_;
    size_t n_;
    size_t i_ = 0;
    std::string where_;
};

// ---- Compression -------------------------------------------------------------------------

std::vector<uint8_t> compress(Compression c, int level, const uint8_t *data, size_t size);
// Decompresses exactly `expected` bytes (the chunk's uncompressed_size); throws naming
// `where` when the data does not decompress to that.
void decompress(const std::string &compression, const uint8_t *data, size_t size, uint8_t *out, size_t expected,
                const std::string &where);

} // namespace binocle::mcap::detail
