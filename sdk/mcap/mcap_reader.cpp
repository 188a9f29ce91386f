// SPDX-License-Identifier: MIT
// mcap::Reader: opens a file by its summary and chunk indexes, or scans its data section
// when it has none (a file cut short, one written without indexes) and recovers every
// complete chunk. Every size is checked against the file and the caps before allocating.
#include "mcap_record_walk.hpp"
#include "mcap_records.hpp"

#include <binocle/text.hpp>

#include <cerrno>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <mutex>

namespace binocle::mcap {

using detail::Cursor;
using detail::kRecordHead;
using detail::MemoryRecords;
using detail::RecordAt;
using detail::walkRecords;

namespace {
constexpr uint64_t kFooterRecord = kRecordHead + 20;

std::string hexOpcode(uint8_t op) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02X", op);
    return buf;
}
} // namespace

struct Reader::Impl {
    std::string path;
    ReaderOptions options;
    int fd = -1;
    uint64_t size = 0;
    std::string profile, library;
    std::map<uint16_t, Schema> schemas;
    std::map<uint16_t, Channel> channels;
    std::vector<ChunkInfo> chunks;
    std::vector<uint64_t> looseMessages; // offsets of Message records outside chunks (scan)
    Statistics stats;

    // Here and not in ~Reader: a file refused while opening (the constructor throws, so
    // ~Reader never runs) still has its descriptor closed.
    ~Impl() {
        if (fd >= 0) ::close(fd);
    }
    bool indexed = false;
    std::string note;
    std::vector<std::pair<std::string, KeyValues>> metadata;

    mutable std::mutex cacheMutex;
    mutable std::vector<std::pair<size_t, std::shared_ptr<const std::vector<uint8_t>>>> cache; // last two chunks

    std::string at(uint64_t offset) const { return "mcap: " + path + ": record at offset " + std::to_string(offset); }

    void readAt(uint64_t offset, uint8_t *out, uint64_t n, const std::string &what) const {
        if (offset > size || n > size - offset)
            throw Error("mcap: " + path + ": " + what + " at offset " + std::to_string(offset) + " needs " +
                            std::to_string(n) + " bytes but the file ends at " + std::to_string(size),
                        static_cast<int64_t>(offset));
        while (n > 0) {
            const ssize_t r = ::pread(fd, out, n, static_cast<off_t>(offset));
            if (r < 0 && errno == EINTR) continue;
            if (r <= 0)
                throw Error("mcap: " + path + ": cannot read " + what + " at offset " + std::to_string(offset) + ": " +
                                (r == 0 ? std::string("unexpected end of file") : std::strerror(errno)),
                            static_cast<int64_t>(offset));
            out += r;
            n -= static_cast<uint64_t>(r);
            offset += static_cast<uint64_t>(r);
        }
    }

    // Opcode and length of the record at `offset`; the length checked against the file
    // and the cap.
    std::pair<uint8_t, uint64_t> head(uint64_t offset, uint64_t limit) const {
        uint8_t h[kRecordHead];
        readAt(offset, h, kRecordHead, "record header");
        uint64_t len = 0;
        for (int i = 0; i < 8; ++i) len |= static_cast<uint64_t>(h[1 + i]) << (8 * i);
        if (len > limit - offset - kRecordHead)
            throw Error(at(offset) + " (opcode " + hexOpcode(h[0]) + ") claims " + std::to_string(len) +
                            " bytes but only " + std::to_string(limit - offset - kRecordHead) + " are left before offset " +
                            std::to_string(limit),
                        static_cast<int64_t>(offset));
        if (len > options.max_record_bytes)
            throw Error(at(offset) + " (opcode " + hexOpcode(h[0]) + ") claims " + std::to_string(len) +
                            " bytes; at most " + std::to_string(options.max_record_bytes) + " are accepted",
                        static_cast<int64_t>(offset));
        return {h[0], len};
    }

    std::vector<uint8_t> body(uint64_t offset, uint64_t len) const {
        std::vector<uint8_t> b(static_cast<size_t>(len));
        readAt(offset + kRecordHead, b.data(), len, "record");
        return b;
    }

    // ---- Records -------------------------------------------------------------------------

    // A Schema or Channel record (its fields: mcap_records.hpp).
    template <class Record>
    static Record parse(Cursor &c) {
        Record r;
        detail::readFields(c, r);
        return r;
    }
    void addSchema(Schema s, const std::string &where) {
        if (s.id == 0) throw Error(where + ": schema id 0 is reserved (no schema); expected 1 or more");
        auto it = schemas.find(s.id);
        if (it != schemas.end() && (it->second.name != s.name || it->second.data != s.data))
            throw Error(where + ": schema " + std::to_string(s.id) + " is defined twice, differently");
        schemas[s.id] = std::move(s);
    }
    void addChannel(Channel c, const std::string &where) {
        if (c.schema_id != 0 && !schemas.count(c.schema_id))
            throw Error(where + ": channel " + std::to_string(c.id) + " ('" + sdk::printable(c.topic) +
                        "') names schema " + std::to_string(c.schema_id) + ", which is not defined before it");
        auto it = channels.find(c.id);
        if (it != channels.end() && it->second.topic != c.topic)
            throw Error(where + ": channel " + std::to_string(c.id) + " is defined twice, with topics '" +
                        sdk::printable(it->second.topic) + "' and '" + sdk::printable(c.topic) + "'");
        channels[c.id] = std::move(c);
    }

    // The fields of a Chunk record up to its records; `c` is then at the records.
    static ChunkInfo parseChunkHead(Cursor &c, uint64_t &recordsLength) {
        ChunkInfo k;
        k.message_start_time = c.u64("chunk message_start_time");
        k.message_end_time = c.u64("chunk message_end_time");
        k.uncompressed_size = c.u64("chunk uncompressed_size");
        c.u32("chunk uncompressed_crc");
        k.compression = c.str("chunk compression");
        recordsLength = c.u64("chunk records length");
        return k;
    }

    // ---- Opening -------------------------------------------------------------------------

    void open() {
        // O_NONBLOCK: a FIFO (or a device) named as the file is refused below, never waited
        // on; on a regular file it changes nothing.
        fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
        if (fd < 0) throw Error("mcap: cannot open " + path + ": " + std::strerror(errno));
        struct stat st {};
        if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
            throw Error("mcap: " + path + " is not a regular file (" + sdk::fileTypeName(st.st_mode) + "); expected an MCAP file");
        size = static_cast<uint64_t>(st.st_size);
        uint8_t magic[8];
        if (size < sizeof magic + kRecordHead)
            throw Error("mcap: " + path + " holds " + std::to_string(size) +
                        " bytes; expected an MCAP file (magic and a Header record)");
        readAt(0, magic, 8, "magic");
        if (std::memcmp(magic, kMagic, 8) != 0)
            throw Error("mcap: " + path + " does not start with the MCAP magic (\\x89MCAP0\\r\\n); expected an MCAP file", 0);
        const auto [op, len] = head(8, size);
        if (op != static_cast<uint8_t>(Opcode::Header))
            throw Error(at(8) + ": opcode " + hexOpcode(op) + "; expected the Header record (0x01)", 8);
        const auto b = body(8, len);
        Cursor c(b.data(), b.size(), at(8) + " (Header)");
        profile = c.str("profile");
        library = c.str("library");
        const uint64_t dataStart = 8 + kRecordHead + len;
        if (!readSummary()) scan(dataStart);
        std::stable_sort(chunks.begin(), chunks.end(), [](const ChunkInfo &a, const ChunkInfo &b) {
            return a.message_start_time < b.message_start_time;
        });
        cache.clear(); // keyed by the index, which the sort changed
    }

    // True when the file has a footer, a summary and chunk indexes for all its chunks.
    bool readSummary() {
        if (size < 8 + kRecordHead + kFooterRecord + 8) {
            note = "the file is too short for a footer";
            return false;
        }
        uint8_t tail[kFooterRecord + 8];
        const uint64_t footerAt = size - sizeof tail;
        readAt(footerAt, tail, sizeof tail, "footer");
        if (std::memcmp(tail + kFooterRecord, kMagic, 8) != 0 || tail[0] != static_cast<uint8_t>(Opcode::Footer)) {
            note = "the file does not end with a footer and the magic (a writer that did not finish)";
            return false;
        }
        Cursor f(tail + 1, kFooterRecord - 1, at(footerAt) + " (Footer)");
        if (f.u64("footer length") != 20) throw Error(at(footerAt) + " (Footer): length is not 20", static_cast<int64_t>(footerAt));
        const uint64_t summaryStart = f.u64("summary_start");
        f.u64("summary_offset_start");
        const uint32_t summaryCrc = f.u32("summary_crc");
        if (summaryStart == 0) {
            note = "the file has no summary section";
            return false;
        }
        if (summaryStart > footerAt || summaryStart < 8 + kRecordHead)
            throw Error(at(footerAt) + " (Footer): summary_start " + std::to_string(summaryStart) +
                            " is outside the file's records (8 .. " + std::to_string(footerAt) + ")",
                        static_cast<int64_t>(footerAt));
        if (footerAt - summaryStart > options.max_summary_bytes)
            throw Error(at(footerAt) + " (Footer): the summary holds " + std::to_string(footerAt - summaryStart) +
                            " bytes; at most " + std::to_string(options.max_summary_bytes) + " are accepted",
                        static_cast<int64_t>(footerAt));
        std::vector<uint8_t> summary(static_cast<size_t>(footerAt - summaryStart + kFooterRecord - 4));
        readAt(summaryStart, summary.data(), summary.size(), "summary");
        if (options.check_crcs && summaryCrc != 0) {
            const uint32_t crc = crc32(summary.data(), summary.size());
            if (crc != summaryCrc)
                throw Error("mcap: " + path + ": the summary (offsets " + std::to_string(summaryStart) + " .. " +
                                std::to_string(footerAt) + ") has CRC " + std::to_string(crc) + " but the footer says " +
                                std::to_string(summaryCrc) + ": the summary is damaged",
                            static_cast<int64_t>(summaryStart));
        }
        bool haveStats = false;
        const MemoryRecords records(summary.data(), static_cast<size_t>(footerAt - summaryStart), summaryStart,
                                    "mcap: " + path + ": record at offset ", "record length", "summary record");
        walkRecords(records, summaryStart, [&](const RecordAt &r) {
            Cursor c = records.fields(r);
            switch (static_cast<Opcode>(r.op)) {
            case Opcode::Schema: addSchema(parse<Schema>(c), at(r.offset)); break;
            case Opcode::Channel: addChannel(parse<Channel>(c), at(r.offset)); break;
            case Opcode::Statistics: parseStatistics(c); haveStats = true; break;
            case Opcode::ChunkIndex: chunks.push_back(parseChunkIndex(c, r.offset)); break;
            case Opcode::MetadataIndex: readMetadata(c, r.offset); break;
            default: break; // attachment indexes, summary offsets, unknown: not needed
            }
            return true;
        });
        if (chunks.empty()) {
            note = "the summary has no chunk indexes";
            chunks.clear();
            return false;
        }
        if (haveStats && stats.chunk_count != chunks.size()) {
            note = "the summary indexes " + std::to_string(chunks.size()) + " of the " +
                   std::to_string(stats.chunk_count) + " chunks its statistics count";
            chunks.clear();
            return false;
        }
        if (!haveStats) countFromChunks();
        indexed = true;
        return true;
    }

    void parseStatistics(Cursor &c) { detail::readFields(c, stats); }

    ChunkInfo parseChunkIndex(Cursor &c, uint64_t offset) {
        ChunkInfo k;
        k.message_start_time = c.u64("message_start_time");
        k.message_end_time = c.u64("message_end_time");
        k.offset = c.u64("chunk_start_offset");
        k.length = c.u64("chunk_length");
        const uint32_t n = c.u32("message_index_offsets length");
        c.skip(n, "message_index_offsets");
        c.u64("message_index_length");
        k.compression = c.str("compression");
        k.compressed_size = c.u64("compressed_size");
        k.uncompressed_size = c.u64("uncompressed_size");
        if (k.offset < 8 || k.offset > size || k.length > size - k.offset || k.length < kRecordHead)
            throw Error(at(offset) + " (Chunk Index): the chunk at offset " + std::to_string(k.offset) + " of " +
                            std::to_string(k.length) + " bytes lies outside the file (" + std::to_string(size) + " bytes)",
                        static_cast<int64_t>(offset));
        return k;
    }

    void readMetadata(Cursor &c, uint64_t offset) {
        const uint64_t at_ = c.u64("metadata offset");
        c.u64("metadata length");
        try {
            const auto [op, len] = head(at_, size);
            if (op != static_cast<uint8_t>(Opcode::Metadata)) return;
            const auto b = body(at_, len);
            Cursor m(b.data(), b.size(), at(at_) + " (Metadata)");
            std::string name = m.str("name");
            metadata.emplace_back(std::move(name), m.map("metadata"));
        } catch (const Error &e) {
            throw Error(at(offset) + " (Metadata Index): " + e.what(), static_cast<int64_t>(offset));
        }
    }

    void countFromChunks() {
        stats.chunk_count = static_cast<uint32_t>(chunks.size());
        stats.schema_count = static_cast<uint16_t>(schemas.size());
        stats.channel_count = static_cast<uint32_t>(channels.size());
        for (size_t i = 0; i < chunks.size(); ++i) {
            stats.message_start_time = i == 0 ? chunks[i].message_start_time
                                              : std::min(stats.message_start_time, chunks[i].message_start_time);
            stats.message_end_time = std::max(stats.message_end_time, chunks[i].message_end_time);
        }
    }

    // The data section in the file, read as the walk goes: its records end at DataEnd or
    // the Footer, and where a record is cut short, claims more bytes than the file or the
    // cap allows, or has opcode 0 (`stop` says which).
    struct FileRecords {
        const Impl &file;
        std::string stop;
        std::vector<uint8_t> body;

        bool head(uint64_t offset, RecordAt &r) {
            const uint64_t left = file.size - offset;
            if (left < kRecordHead) {
                stop = left > 0 ? "the last " + std::to_string(left) + " bytes are not a record"
                                : "the file ends after a complete record";
                return false;
            }
            try {
                std::tie(r.op, r.length) = file.head(offset, file.size);
            } catch (const Error &e) {
                stop = e.what();
                return false;
            }
            r.offset = offset;
            if (r.op == 0) stop = file.at(offset) + " has opcode 0x00 (no record starts so)";
            return r.op != 0 && !r.is(Opcode::DataEnd) && !r.is(Opcode::Footer);
        }
        Cursor fields(const RecordAt &r) {
            body = file.body(r.offset, r.length);
            return Cursor(body.data(), body.size(), file.at(r.offset));
        }
    };

    // Reads the data section record by record from `offset`; a record cut short ends the
    // scan (what came before is kept). Chunks are decompressed and checked here, so that
    // the schemas and channels inside them are known and a damaged last chunk is left out.
    void scan(uint64_t offset) {
        const std::string why = note;
        stats = Statistics{};
        std::string stop;
        FileRecords data{*this, {}, {}};
        walkRecords(data, offset, [&](const RecordAt &r) {
            if (r.is(Opcode::Chunk)) {
                try {
                    scanChunk(r.offset, r.length);
                } catch (const Error &e) {
                    stop = e.what();
                    return false;
                }
            } else if (r.is(Opcode::Schema) || r.is(Opcode::Channel) || r.is(Opcode::Message) || r.is(Opcode::Metadata)) {
                Cursor c = data.fields(r);
                if (r.is(Opcode::Schema)) addSchema(parse<Schema>(c), at(r.offset));
                else if (r.is(Opcode::Channel)) addChannel(parse<Channel>(c), at(r.offset));
                else if (r.is(Opcode::Metadata)) {
                    std::string name = c.str("name");
                    metadata.emplace_back(std::move(name), c.map("metadata"));
                } else {
                    countMessage(c, at(r.offset));
                    looseMessages.push_back(r.offset);
                }
            }
            return true;
        });
        if (stop.empty()) stop = data.stop;
        stats.chunk_count = static_cast<uint32_t>(chunks.size());
        stats.schema_count = static_cast<uint16_t>(schemas.size());
        stats.channel_count = static_cast<uint32_t>(channels.size());
        note = why + "; scanned the data section: " + std::to_string(chunks.size()) + " chunk(s), " +
               std::to_string(stats.message_count) + " message(s) recovered" + (stop.empty() ? "" : "; stopped: " + stop);
    }

    void countMessage(Cursor &c, const std::string &where) {
        const uint16_t ch = c.u16("channel_id");
        c.u32("sequence");
        const uint64_t t = c.u64("log_time");
        if (!channels.count(ch))
            throw Error(where + ": message on channel " + std::to_string(ch) + ", which is not defined before it");
        stats.message_start_time = stats.message_count == 0 ? t : std::min(stats.message_start_time, t);
        stats.message_end_time = std::max(stats.message_end_time, t);
        ++stats.message_count;
        ++stats.channel_message_counts[ch];
    }

    void scanChunk(uint64_t offset, uint64_t len) {
        ChunkInfo k;
        k.offset = offset;
        k.length = kRecordHead + len;
        // The fixed fields and the compression name: at most 36 + 4 + a short name.
        std::vector<uint8_t> h(static_cast<size_t>(std::min<uint64_t>(len, 300)));
        readAt(offset + kRecordHead, h.data(), h.size(), "chunk");
        Cursor c(h.data(), h.size(), at(offset) + " (Chunk)");
        uint64_t recordsLength = 0;
        const ChunkInfo head_ = parseChunkHead(c, recordsLength);
        k.message_start_time = head_.message_start_time;
        k.message_end_time = head_.message_end_time;
        k.uncompressed_size = head_.uncompressed_size;
        k.compression = head_.compression;
        k.compressed_size = recordsLength;
        if (recordsLength != len - c.pos())
            throw Error(at(offset) + " (Chunk): its records claim " + std::to_string(recordsLength) + " bytes but the record leaves " +
                            std::to_string(len - c.pos()),
                        static_cast<int64_t>(offset));
        chunks.push_back(k);
        const size_t index = chunks.size() - 1;
        // Statistics are counted only once the whole chunk is known good.
        const Statistics before = stats;
        try {
            const auto records = load(index);
            walkChunk(*records, offset, [&](const RecordAt &record, Cursor &r) {
                const std::string where = at(offset) + " (Chunk), inner record at " + std::to_string(record.offset);
                if (record.is(Opcode::Schema)) addSchema(parse<Schema>(r), where);
                else if (record.is(Opcode::Channel)) addChannel(parse<Channel>(r), where);
                else if (record.is(Opcode::Message)) countMessage(r, where);
            });
        } catch (...) {
            chunks.pop_back();
            cache.clear();
            stats = before;
            throw;
        }
    }

    // Calls visit(record, cursor over its fields) for each of a chunk's records (their
    // offsets in the records).
    template <typename Visit> void walkChunk(const std::vector<uint8_t> &records, uint64_t chunkOffset, Visit &&visit) const {
        const MemoryRecords span(records.data(), records.size(), 0, at(chunkOffset) + " (Chunk): inner record at ",
                                 "length", "inner record");
        walkRecords(span, 0, [&](const RecordAt &r) {
            Cursor c = span.fields(r);
            visit(r, c);
            return true;
        });
    }

    // The chunk's records, decompressed and CRC-checked.
    std::shared_ptr<const std::vector<uint8_t>> load(size_t index) const {
        {
            std::lock_guard<std::mutex> lock(cacheMutex);
            for (const auto &[i, records] : cache)
                if (i == index) return records;
        }
        const ChunkInfo &k = chunks.at(index);
        const std::string where = at(k.offset) + " (Chunk)";
        const auto [op, len] = head(k.offset, size);
        if (op != static_cast<uint8_t>(Opcode::Chunk))
            throw Error(where + ": opcode " + hexOpcode(op) + "; the chunk index points at a Chunk record (0x06)",
                        static_cast<int64_t>(k.offset));
        if (k.uncompressed_size > options.max_record_bytes)
            throw Error(where + ": uncompressed_size " + std::to_string(k.uncompressed_size) + " bytes; at most " +
                            std::to_string(options.max_record_bytes) + " are accepted",
                        static_cast<int64_t>(k.offset));
        const auto b = body(k.offset, len);
        Cursor c(b.data(), b.size(), where);
        uint64_t recordsLength = 0;
        ChunkInfo fields = parseChunkHead(c, recordsLength);
        const uint32_t crc = [&] {
            Cursor again(b.data() + 24, 4, where);
            return again.u32("uncompressed_crc");
        }();
        const uint8_t *data = c.run(recordsLength, "chunk records");
        if (fields.uncompressed_size > options.max_record_bytes)
            throw Error(where + ": uncompressed_size " + std::to_string(fields.uncompressed_size) + " bytes; at most " +
                            std::to_string(options.max_record_bytes) + " are accepted",
                        static_cast<int64_t>(k.offset));
        // No compressor makes data more than ~32768 times smaller (zstd: a 128 KiB block
        // costs at least 4 bytes; lz4: ~255): a size far beyond that is a lie, refused
        // before it is allocated.
        if (fields.compression.empty() && fields.uncompressed_size != recordsLength)
            throw Error(where + ": uncompressed_size " + std::to_string(fields.uncompressed_size) +
                            " but the chunk records of an uncompressed chunk hold " + std::to_string(recordsLength) +
                            " bytes; expected the same",
                        static_cast<int64_t>(k.offset));
        const uint64_t maxRatio = fields.compression == "lz4" ? 256 : 32768;
        if (!fields.compression.empty() && fields.uncompressed_size > recordsLength * maxRatio + (uint64_t{1} << 16))
            throw Error(where + ": uncompressed_size " + std::to_string(fields.uncompressed_size) + " from " +
                            std::to_string(recordsLength) + " compressed bytes is more than any " +
                            sdk::printable(fields.compression, 20) + " chunk can hold",
                        static_cast<int64_t>(k.offset));
        auto out = std::make_shared<std::vector<uint8_t>>(static_cast<size_t>(fields.uncompressed_size));
        detail::decompress(fields.compression, data, static_cast<size_t>(recordsLength), out->data(), out->size(), where);
        if (options.check_crcs && crc != 0) {
            const uint32_t actual = crc32(out->data(), out->size());
            if (actual != crc)
                throw Error(where + ": its records have CRC " + std::to_string(actual) + " but the chunk says " +
                                std::to_string(crc) + ": the chunk is damaged",
                            static_cast<int64_t>(k.offset));
        }
        std::lock_guard<std::mutex> lock(cacheMutex);
        cache.emplace_back(index, out);
        if (cache.size() > 2) cache.erase(cache.begin());
        return out;
    }

    static MessageView parseMessage(Cursor &r) {
        MessageView m;
        const uint16_t ch = r.u16("channel_id");
        m.sequence = r.u32("sequence");
        m.log_time = r.u64("log_time");
        m.publish_time = r.u64("publish_time");
        m.data = r.here();
        m.size = r.left();
        m.record_offset = ch; // the channel id until resolved by the caller
        return m;
    }

    const Channel *channelOf(uint16_t id, const std::string &where) const {
        auto it = channels.find(id);
        if (it == channels.end())
            throw Error(where + ": message on channel " + std::to_string(id) + ", which no Channel record defines");
        return &it->second;
    }
};

Reader::Reader(const std::string &path, ReaderOptions options) : impl_(std::make_unique<Impl>()) {
    impl_->path = path;
    impl_->options = options;
    impl_->open();
}

Reader::~Reader() = default;

const std::string &Reader::path() const { return impl_->path; }
const std::string &Reader::profile() const { return impl_->profile; }
const std::string &Reader::library() const { return impl_->library; }
const std::map<uint16_t, Schema> &Reader::schemas() const { return impl_->schemas; }
const std::map<uint16_t, Channel> &Reader::channels() const { return impl_->channels; }
const std::vector<ChunkInfo> &Reader::chunks() const { return impl_->chunks; }
const Statistics &Reader::statistics() const { return impl_->stats; }
bool Reader::indexed() const { return impl_->indexed; }
const std::string &Reader::recoveryNote() const {
    static const std::string none;
    return impl_->indexed ? none : impl_->note;
}
const std::vector<std::pair<std::string, KeyValues>> &Reader::metadata() const { return impl_->metadata; }

const Channel *Reader::channelByTopic(const std::string &topic) const {
    for (const auto &[id, c] : impl_->channels)
        if (c.topic == topic) return &c;
    return nullptr;
}

const Schema *Reader::schemaOf(const Channel &channel) const {
    auto it = impl_->schemas.find(channel.schema_id);
    return it == impl_->schemas.end() ? nullptr : &it->second;
}

std::shared_ptr<const std::vector<uint8_t>> Reader::chunkRecords(size_t chunk_index) const {
    return impl_->load(chunk_index);
}

void Reader::readMessages(const std::function<bool(const MessageView &)> &visit, const std::vector<uint16_t> &channel_ids,
                          uint64_t start_ns, uint64_t end_ns) const {
    const Impl &r = *impl_;
    auto wanted = [&](uint16_t ch) {
        return channel_ids.empty() || std::find(channel_ids.begin(), channel_ids.end(), ch) != channel_ids.end();
    };
    // Chunks and messages outside chunks, in time order.
    struct Unit {
        uint64_t time;
        size_t chunk;    // SIZE_MAX: a loose message
        uint64_t offset; // of the loose message
    };
    std::vector<Unit> units;
    for (size_t i = 0; i < r.chunks.size(); ++i)
        if (r.chunks[i].message_end_time >= start_ns && r.chunks[i].message_start_time <= end_ns)
            units.push_back({r.chunks[i].message_start_time, i, 0});
    for (uint64_t o : r.looseMessages) {
        std::shared_ptr<const std::vector<uint8_t>> hold;
        const MessageView m = messageAt(SIZE_MAX, static_cast<int64_t>(o), hold);
        if (m.log_time >= start_ns && m.log_time <= end_ns && wanted(m.channel->id)) units.push_back({m.log_time, SIZE_MAX, o});
    }
    std::stable_sort(units.begin(), units.end(), [](const Unit &a, const Unit &b) { return a.time < b.time; });
    for (const Unit &u : units) {
        if (u.chunk == SIZE_MAX) {
            std::shared_ptr<const std::vector<uint8_t>> hold;
            if (!visit(messageAt(SIZE_MAX, static_cast<int64_t>(u.offset), hold))) return;
            continue;
        }
        const ChunkInfo &k = r.chunks[u.chunk];
        const auto records = r.load(u.chunk);
        std::vector<MessageView> found;
        r.walkChunk(*records, k.offset, [&](const RecordAt &record, detail::Cursor &c) {
            if (!record.is(Opcode::Message)) return;
            const uint64_t at = record.offset;
            MessageView m = Impl::parseMessage(c);
            const auto ch = static_cast<uint16_t>(m.record_offset);
            if (!wanted(ch) || m.log_time < start_ns || m.log_time > end_ns) return;
            m.channel = r.channelOf(ch, r.at(k.offset) + " (Chunk): inner record at " + std::to_string(at));
            m.record_offset = static_cast<int64_t>(at);
            m.chunk_offset = static_cast<int64_t>(k.offset);
            found.push_back(m);
        });
        std::stable_sort(found.begin(), found.end(),
                         [](const MessageView &a, const MessageView &b) { return a.log_time < b.log_time; });
        for (const MessageView &m : found)
            if (!visit(m)) return;
    }
}

MessageView Reader::messageAt(size_t chunk_index, int64_t record_offset,
                              std::shared_ptr<const std::vector<uint8_t>> &hold) const {
    const Impl &r = *impl_;
    if (chunk_index == SIZE_MAX) {
        const auto o = static_cast<uint64_t>(record_offset);
        const auto [op, len] = r.head(o, r.size);
        if (op != static_cast<uint8_t>(Opcode::Message))
            throw Error(r.at(o) + ": opcode " + hexOpcode(op) + "; expected a Message record (0x05)", record_offset);
        auto b = std::make_shared<std::vector<uint8_t>>(r.body(o, len));
        detail::Cursor c(b->data(), b->size(), r.at(o) + " (Message)");
        MessageView m = Impl::parseMessage(c);
        m.channel = r.channelOf(static_cast<uint16_t>(m.record_offset), r.at(o));
        m.record_offset = record_offset;
        hold = b;
        return m;
    }
    const auto records = r.load(chunk_index);
    const ChunkInfo &k = r.chunks.at(chunk_index);
    const std::string where = r.at(k.offset) + " (Chunk): inner record at " + std::to_string(record_offset);
    if (record_offset < 0 || static_cast<uint64_t>(record_offset) >= records->size()) throw Error(where + ": outside the chunk");
    detail::Cursor h(records->data() + record_offset, records->size() - static_cast<size_t>(record_offset), where);
    if (h.u8("opcode") != static_cast<uint8_t>(Opcode::Message)) throw Error(where + ": not a Message record (0x05)");
    const uint64_t len = h.u64("length");
    detail::Cursor c(h.run(len, "message"), static_cast<size_t>(len), where);
    MessageView m = Impl::parseMessage(c);
    m.channel = r.channelOf(static_cast<uint16_t>(m.record_offset), where);
    m.record_offset = record_offset;
    m.chunk_offset = static_cast<int64_t>(k.offset);
    hold = records;
    return m;
}

} // namespace binocle::mcap
