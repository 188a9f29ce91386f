// SPDX-License-Identifier: MIT
// The records that both ends of libbinocle_mcap handle field by field (Schema, Channel,
// Statistics), each described once by `recordFields(const R *)`: its fields in file
// order, each with the name a read error gives. putFields() and readFields() both walk
// that list, so that the writer and the reader cannot drift (as the isolation codec's
// wireFields). Internal to libbinocle_mcap.
#pragma once

#include "mcap_bytes.hpp"

#include <cstdint>
#include <map>
#include <string>
#include <tuple>
#include <type_traits>

namespace binocle::mcap::detail {

// A number, a text (4-byte length, then its bytes) or a key/value map.
template <class R, class V>
struct Field {
    V R::*member;
    const char *name;
};
template <class R, class V>
constexpr Field<R, V> field(V R::*member, const char *name) {
    return {member, name};
}

// Bytes, or pairs of channel id and number, with their size before them (4 bytes); a read
// error names the size or the run.
template <class R, class V>
struct Sized {
    V R::*member;
    const char *sizeName, *name;
};
template <class R, class V>
constexpr Sized<R, V> sized(V R::*member, const char *sizeName, const char *name) {
    return {member, sizeName, name};
}

// ---- The descriptions ---------------------------------------------------------------------

inline auto recordFields(const Schema *) {
    return std::make_tuple(field(&Schema::id, "schema id"), field(&Schema::name, "schema name"),
                           field(&Schema::encoding, "schema encoding"),
                           sized(&Schema::data, "schema data length", "schema data"));
}

inline auto recordFields(const Channel *) {
    return std::make_tuple(field(&Channel::id, "channel id"), field(&Channel::schema_id, "channel schema_id"),
                           field(&Channel::topic, "channel topic"),
                           field(&Channel::message_encoding, "channel message_encoding"),
                           field(&Channel::metadata, "channel metadata"));
}

inline auto recordFields(const Statistics *) {
    using S = Statistics;
    return std::make_tuple(field(&S::message_count, "message_count"), field(&S::schema_count, "schema_count"),
                           field(&S::channel_count, "channel_count"), field(&S::attachment_count, "attachment_count"),
                           field(&S::metadata_count, "metadata_count"), field(&S::chunk_count, "chunk_count"),
                           field(&S::message_start_time, "message_start_time"),
                           field(&S::message_end_time, "message_end_time"),
                           sized(&S::channel_message_counts, "channel_message_counts length", "channel_message_counts"));
}

// ---- Writing --------------------------------------------------------------------------------

template <class R, class V>
void putField(Bytes &b, const R &r, const Field<R, V> &f) {
    const V &v = r.*f.member;
    if constexpr (std::is_integral_v<V>) b.le(v);
    else if constexpr (std::is_same_v<V, std::string>) b.str(v);
    else b.map(v);
}

template <class R, class V>
void putField(Bytes &b, const R &r, const Sized<R, V> &f) {
    const V &v = r.*f.member;
    if constexpr (std::is_same_v<V, std::string>) {
        b.u32(static_cast<uint32_t>(v.size()));
        b.raw(v.data(), v.size());
    } else {
        b.channelMap(v);
    }
}

template <class R>
void putFields(Bytes &b, const R &r) {
    std::apply([&](const auto &...f) { (putField(b, r, f), ...); }, recordFields(&r));
}

// ---- Reading --------------------------------------------------------------------------------

template <class R, class V>
void readField(Cursor &c, R &r, const Field<R, V> &f) {
    V &v = r.*f.member;
    if constexpr (std::is_integral_v<V>) v = c.le<V>(f.name);
    else if constexpr (std::is_same_v<V, std::string>) v = c.str(f.name);
    else v = c.map(f.name);
}

template <class R, class V>
void readField(Cursor &c, R &r, const Sized<R, V> &f) {
    V &v = r.*f.member;
    const uint32_t n = c.u32(f.sizeName);
    const uint8_t *d = c.run(n, f.name);
    if constexpr (std::is_same_v<V, std::string>) {
        v.assign(reinterpret_cast<const char *>(d), n);
    } else { // Statistics' message counts, the only such field read
        Cursor pairs(d, n, "statistics");
        while (pairs.left() > 0) {
            const uint16_t channel = pairs.u16("channel id");
            v[channel] = pairs.u64("message count");
        }
    }
}

// Reads the fields into `r`: a field past the record's end throws, naming the field.
template <class R>
void readFields(Cursor &c, R &r) {
    std::apply([&](const auto &...f) { (readField(c, r, f), ...); }, recordFields(&r));
}

} // namespace binocle::mcap::detail
