// SPDX-License-Identifier: MIT
// mcap::Writer: chunked, compressed MCAP with message indexes, a summary with chunk
// indexes and statistics, and a footer; each chunk whole on disk (and fsync'ed) before
// the next one starts, so that a writer killed at any moment leaves a readable file.
#include "mcap_records.hpp"

#include <cerrno>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>

namespace binocle::mcap {

using detail::Bytes;

struct Writer::Impl {
    std::string path;
    WriterOptions options;
    int fd = -1;
    uint64_t offset = 0;  // bytes in the file
    uint32_t dataCrc = 0; // of everything before Data End
    bool closed = false;
    std::string broken;           // why an earlier write failed; nothing is appended after it
    uint64_t durableMessages = 0; // messages in chunks written whole (and fsync'ed)

    std::vector<Schema> schemas;
    std::vector<Channel> channels;
    std::vector<std::pair<std::string, KeyValues>> metadata;
    Statistics stats;

    // The open chunk: its records, and per channel the (log time, offset) of its messages.
    Bytes chunk;
    uint64_t chunkStart = UINT64_MAX, chunkEnd = 0;
    std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunkIndex;
    size_t chunkMessages = 0;

    Bytes chunkIndexes; // Chunk Index records, for the summary

    std::string where() const { return "mcap: " + path; }

    // Writes the bytes whole or not at all: a write cut short (a full disk, the file size
    // limit) is cut back off the file, so that the file ends with its last whole record and
    // a reader recovers exactly what durableMessages counts; the writer then refuses more.
    void writeAll(const uint8_t *p, size_t n, bool data = true) {
        if (!broken.empty()) throw Error(where() + ": an earlier write failed (" + broken + "); nothing more is written");
        const uint64_t start = offset;
        const uint32_t crcBefore = dataCrc;
        while (n > 0) {
            const ssize_t w = ::write(fd, p, n);
            if (w < 0 && errno == EINTR) continue;
            if (w <= 0) { // write() returning 0 sets no errno
                broken = w < 0 ? std::strerror(errno) : "no byte written (is the disk full?)";
                const bool cut = ::ftruncate(fd, static_cast<off_t>(start)) == 0;
                if (cut) offset = start;
                dataCrc = crcBefore;
                throw Error(where() + ": cannot write at offset " + std::to_string(start) + ": " + broken +
                                (cut ? "; the file ends with its last whole record" : ""),
                            static_cast<int64_t>(start));
            }
            if (data) dataCrc = crc32(p, static_cast<size_t>(w), dataCrc);
            p += w;
            n -= static_cast<size_t>(w);
            offset += static_cast<uint64_t>(w);
        }
    }
    void writeAll(const Bytes &b, bool data = true) { writeAll(b.b.data(), b.b.size(), data); }

    // fsync; when it fails the bytes since `start` are not known to be on disk: they are
    // cut off, as a failed write is.
    void sync(uint64_t start) {
        if (!options.sync_chunks || ::fsync(fd) == 0) return;
        broken = std::string("fsync failed: ") + std::strerror(errno);
        if (::ftruncate(fd, static_cast<off_t>(start)) == 0) offset = start;
        throw Error(where() + ": " + broken, static_cast<int64_t>(offset));
    }

    // A Schema, Channel or Statistics record (its fields: mcap_records.hpp).
    template <class Record>
    static void putRecord(Bytes &b, Opcode op, const Record &r) {
        const size_t at = b.begin(op);
        detail::putFields(b, r);
        b.end(at);
    }

    // A new schema or channel: written at once, before any chunk that uses it (a stream
    // reader meets it first), kept for the summary and counted. Returns its id.
    template <class Record, class Count>
    uint16_t add(std::vector<Record> &kept, Opcode op, Record r, Count &count) {
        Bytes b;
        putRecord(b, op, r);
        writeAll(b);
        kept.push_back(std::move(r));
        ++count;
        return kept.back().id;
    }

    void flushChunk() {
        if (chunkMessages == 0) return;
        const std::vector<uint8_t> &records = chunk.b;
        const uint32_t crc = crc32(records.data(), records.size());
        const std::vector<uint8_t> packed = detail::compress(options.compression, options.compression_level,
                                                             records.data(), records.size());
        Bytes out;
        const uint64_t chunkOffset = offset;
        const size_t at = out.begin(Opcode::Chunk);
        out.u64(chunkStart);
        out.u64(chunkEnd);
        out.u64(records.size());
        out.u32(crc);
        out.str(compressionName(options.compression));
        out.u64(packed.size());
        out.raw(packed.data(), packed.size());
        out.end(at);
        const uint64_t chunkLength = out.b.size();
        // Message Index records follow their chunk, one per channel.
        std::vector<std::pair<uint16_t, uint64_t>> indexOffsets;
        if (options.message_indexes)
            for (auto &[channel, entries] : chunkIndex) {
                std::stable_sort(entries.begin(), entries.end(),
                                 [](const auto &a, const auto &b) { return a.first < b.first; });
                indexOffsets.emplace_back(channel, chunkOffset + out.b.size());
                const size_t mi = out.begin(Opcode::MessageIndex);
                out.u16(channel);
                out.u32(static_cast<uint32_t>(entries.size() * 16));
                for (const auto &[t, o] : entries) {
                    out.u64(t);
                    out.u64(o);
                }
                out.end(mi);
            }
        const uint64_t indexLength = out.b.size() - chunkLength;
        const uint32_t crcBefore = dataCrc;
        writeAll(out);
        try {
            sync(chunkOffset);
        } catch (...) {
            dataCrc = crcBefore;
            throw;
        }
        durableMessages += chunkMessages;

        const size_t ci = chunkIndexes.begin(Opcode::ChunkIndex);
        chunkIndexes.u64(chunkStart);
        chunkIndexes.u64(chunkEnd);
        chunkIndexes.u64(chunkOffset);
        chunkIndexes.u64(chunkLength);
        chunkIndexes.channelMap(indexOffsets);
        chunkIndexes.u64(indexLength);
        chunkIndexes.str(compressionName(options.compression));
        chunkIndexes.u64(packed.size());
        chunkIndexes.u64(records.size());
        chunkIndexes.end(ci);
        ++stats.chunk_count;

        chunk.b.clear();
        chunkIndex.clear();
        chunkMessages = 0;
        chunkStart = UINT64_MAX;
        chunkEnd = 0;
    }

    void finish() {
        flushChunk();
        Bytes tail;
        std::vector<std::pair<uint64_t, uint64_t>> metadataAt; // offset, length
        for (const auto &[name, values] : metadata) {
            const uint64_t at = offset + tail.b.size();
            const size_t r = tail.begin(Opcode::Metadata);
            tail.str(name);
            tail.map(values);
            tail.end(r);
            metadataAt.emplace_back(at, offset + tail.b.size() - at);
        }
        writeAll(tail);
        Bytes end;
        const size_t de = end.begin(Opcode::DataEnd);
        end.u32(dataCrc);
        end.end(de);
        writeAll(end, false);

        // The summary: one group per record kind, each found by a Summary Offset record.
        const uint64_t summaryStart = offset;
        Bytes s;
        std::vector<std::tuple<Opcode, uint64_t, uint64_t>> groups;
        auto group = [&](Opcode op, const std::function<void()> &fill) {
            const uint64_t start = summaryStart + s.b.size();
            fill();
            const uint64_t length = summaryStart + s.b.size() - start;
            if (length > 0) groups.emplace_back(op, start, length);
        };
        group(Opcode::Schema, [&] {
            for (const Schema &x : schemas) putRecord(s, Opcode::Schema, x);
        });
        group(Opcode::Channel, [&] {
            for (const Channel &x : channels) putRecord(s, Opcode::Channel, x);
        });
        group(Opcode::Statistics, [&] { putRecord(s, Opcode::Statistics, stats); });
        if (options.chunk_indexes)
            group(Opcode::ChunkIndex, [&] { s.raw(chunkIndexes.b.data(), chunkIndexes.b.size()); });
        group(Opcode::MetadataIndex, [&] {
            for (size_t i = 0; i < metadata.size(); ++i) {
                const size_t r = s.begin(Opcode::MetadataIndex);
                s.u64(metadataAt[i].first);
                s.u64(metadataAt[i].second);
                s.str(metadata[i].first);
                s.end(r);
            }
        });
        const uint64_t summaryOffsetStart = summaryStart + s.b.size();
        for (const auto &[op, start, length] : groups) {
            const size_t r = s.begin(Opcode::SummaryOffset);
            s.u8(static_cast<uint8_t>(op));
            s.u64(start);
            s.u64(length);
            s.end(r);
        }
        s.u8(static_cast<uint8_t>(Opcode::Footer));
        s.u64(20);
        s.u64(summaryStart);
        s.u64(summaryOffsetStart);
        // The summary CRC covers the summary, the offsets and the footer up to this field.
        s.u32(crc32(s.b.data(), s.b.size()));
        s.raw(kMagic, sizeof kMagic);
        writeAll(s, false);
        if (::fsync(fd) != 0) throw Error(where() + ": fsync failed: " + std::strerror(errno));
    }
};

Writer::Writer(const std::string &path, WriterOptions options) : impl_(std::make_unique<Impl>()) {
    impl_->path = path;
    impl_->options = std::move(options);
    // O_EXCL: an existing file (or a planted symlink) is never written through.
    impl_->fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (impl_->fd < 0) {
        const int err = errno; // read once: building the message may change it
        throw Error("mcap: cannot create " + path + ": " + std::strerror(err) +
                    (err == EEXIST ? " (an existing file is never overwritten)" : ""));
    }
    Bytes head;
    head.raw(kMagic, sizeof kMagic);
    const size_t h = head.begin(Opcode::Header);
    head.str(impl_->options.profile);
    head.str(impl_->options.library);
    head.end(h);
    try {
        impl_->writeAll(head);
    } catch (...) {
        // The constructor throws, so ~Writer never runs: no descriptor kept open, and no
        // half-written file (this writer made it, O_EXCL) left behind.
        ::close(impl_->fd);
        impl_->fd = -1;
        ::unlink(path.c_str());
        throw;
    }
}

Writer::~Writer() {
    if (!impl_ || impl_->closed) return;
    try {
        close();
    } catch (...) {
        // Destructors do not throw; what was flushed before stays readable.
    }
    if (impl_->fd >= 0) ::close(impl_->fd);
}

uint16_t Writer::addSchema(const std::string &name, const std::string &encoding, const std::string &data) {
    for (const Schema &s : impl_->schemas)
        if (s.name == name && s.encoding == encoding && s.data == data) return s.id;
    return impl_->add(impl_->schemas, Opcode::Schema,
                      Schema{static_cast<uint16_t>(impl_->schemas.size() + 1), name, encoding, data},
                      impl_->stats.schema_count);
}

uint16_t Writer::addChannel(uint16_t schema_id, const std::string &topic, const std::string &message_encoding,
                            const KeyValues &metadata) {
    if (schema_id != 0 && schema_id > impl_->schemas.size())
        throw Error(impl_->where() + ": channel '" + topic + "' names schema " + std::to_string(schema_id) +
                    ", which was not added");
    for (const Channel &c : impl_->channels)
        if (c.topic == topic) {
            if (c.schema_id != schema_id || c.message_encoding != message_encoding)
                throw Error(impl_->where() + ": topic '" + topic + "' was added before with another schema or encoding");
            return c.id;
        }
    return impl_->add(impl_->channels, Opcode::Channel,
                      Channel{static_cast<uint16_t>(impl_->channels.size()), schema_id, topic, message_encoding, metadata},
                      impl_->stats.channel_count);
}

void Writer::write(uint16_t channel_id, uint32_t sequence, uint64_t log_time, uint64_t publish_time,
                   const uint8_t *data, size_t size) {
    Impl &w = *impl_;
    if (w.closed) throw Error(w.where() + ": write after close");
    if (channel_id >= w.channels.size())
        throw Error(w.where() + ": message on channel " + std::to_string(channel_id) + ", which was not added");
    // A chunk that would span more than chunk_span_ns is closed first: readers seek by time.
    if (w.chunkMessages > 0 && log_time > w.chunkStart && log_time - w.chunkStart > w.options.chunk_span_ns)
        w.flushChunk();
    Bytes &c = w.chunk;
    w.chunkIndex[channel_id].emplace_back(log_time, c.b.size());
    const size_t r = c.begin(Opcode::Message);
    c.u16(channel_id);
    c.u32(sequence);
    c.u64(log_time);
    c.u64(publish_time);
    c.raw(data, size);
    c.end(r);
    ++w.chunkMessages;
    w.chunkStart = std::min(w.chunkStart, log_time);
    w.chunkEnd = std::max(w.chunkEnd, log_time);
    Statistics &s = w.stats;
    s.message_start_time = s.message_count == 0 ? log_time : std::min(s.message_start_time, log_time);
    s.message_end_time = std::max(s.message_end_time, log_time);
    ++s.message_count;
    ++s.channel_message_counts[channel_id];
    if (c.b.size() >= w.options.chunk_bytes) w.flushChunk();
}

void Writer::addMetadata(const std::string &name, const KeyValues &values) {
    impl_->metadata.emplace_back(name, values);
    ++impl_->stats.metadata_count;
}

void Writer::flush() { impl_->flushChunk(); }

void Writer::close() {
    Impl &w = *impl_;
    if (w.closed) return;
    w.closed = true; // even when finishing fails: nothing more is appended
    w.finish();
    const int fd = w.fd;
    w.fd = -1;
    if (::close(fd) != 0) throw Error(w.where() + ": close failed: " + std::strerror(errno));
}

const Statistics &Writer::statistics() const { return impl_->stats; }
uint64_t Writer::durableMessageCount() const { return impl_->durableMessages; }
uint64_t Writer::bytesWritten() const { return impl_->offset; }
const std::string &Writer::path() const { return impl_->path; }

} // namespace binocle::mcap
