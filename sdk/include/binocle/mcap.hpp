// SPDX-License-Identifier: MIT
// MCAP files (https://mcap.dev/spec): a writer and a reader of the container that rosbag2
// stores its bags in, written from the specification, with zstd and lz4 chunks.
//
// Library: Binocle::mcap (libbinocle_mcap.a, installed with the SDK; links -lzstd -llz4).
// The ROS 2 messages that travel in it (CDR) are in <binocle/ros2_messages.hpp>.
//
// What the writer leaves on disk, and what a reader of a file cut short gets back:
//   magic, Header, then per chunk: the Schema and Channel records it is the first to use,
//   the Chunk record, its Message Index records. Each chunk is written whole and, with
//   `sync_chunks`, fsync'ed, so a writer killed at any moment leaves a file whose every
//   chunk before the cut is complete. close() writes Data End (with the data CRC), the
//   summary (schemas, channels, statistics, chunk indexes, metadata indexes), the
//   summary offsets, the footer and the closing magic.
//   The Reader uses the summary when the file has one; otherwise (a file cut short, or
//   written without chunk indexes) it scans the data section and recovers every record up
//   to the first incomplete one, saying so in recoveryNote().
//
// Untrusted input: every length is checked against the bytes that are left and against
// ReaderOptions' caps before anything is allocated; every fault throws mcap::Error naming
// the file, the record's offset and what was expected. Nothing read from the file is put
// into a message except through sdk::printable.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace binocle::mcap {

// The 8 bytes a file starts and ends with.
inline constexpr char kMagic[8] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum class Opcode : uint8_t {
    Header = 0x01,
    Footer = 0x02,
    Schema = 0x03,
    Channel = 0x04,
    Message = 0x05,
    Chunk = 0x06,
    MessageIndex = 0x07,
    ChunkIndex = 0x08,
    Attachment = 0x09,
    AttachmentIndex = 0x0A,
    Statistics = 0x0B,
    Metadata = 0x0C,
    MetadataIndex = 0x0D,
    SummaryOffset = 0x0E,
    DataEnd = 0x0F,
};

// A fault in a file: the text names the file, the offset of the record and what was
// expected. `offset()` is -1 when the fault has no place in the file (cannot open it).
class Error : public std::runtime_error {
public:
    Error(const std::string &message, int64_t offset = -1) : std::runtime_error(message), offset_(offset) {}
    int64_t offset() const noexcept { return offset_; }

private:
    int64_t offset_;
};

using KeyValues = std::vector<std::pair<std::string, std::string>>;

struct Schema {
    uint16_t id = 0;
    std::string name;     // e.g. "sensor_msgs/msg/Image"
    std::string encoding; // e.g. "ros2msg"
    std::string data;     // e.g. the message definition text
};

struct Channel {
    uint16_t id = 0;
    uint16_t schema_id = 0;
    std::string topic;
    std::string message_encoding; // e.g. "cdr"
    KeyValues metadata;
};

// A message as read: `data` points into the reader's buffer of the chunk it came from,
// valid during the callback only.
struct MessageView {
    const Channel *channel = nullptr;
    uint32_t sequence = 0;
    uint64_t log_time = 0, publish_time = 0; // ns
    const uint8_t *data = nullptr;
    size_t size = 0;
    int64_t record_offset = 0; // of the Message record: in the file, or in its chunk's records
    int64_t chunk_offset = -1; // of the Chunk record holding it; -1 when outside any chunk
};

struct Statistics {
    uint64_t message_count = 0;
    uint16_t schema_count = 0;
    uint32_t channel_count = 0, attachment_count = 0, metadata_count = 0, chunk_count = 0;
    uint64_t message_start_time = 0, message_end_time = 0;
    std::map<uint16_t, uint64_t> channel_message_counts;
};

// ---- Writer --------------------------------------------------------------------------------

enum class Compression { None, Zstd, Lz4 };

// "zstd", "lz4" or "" (none): the names the format uses.
const char *compressionName(Compression c);

struct WriterOptions {
    std::string profile = "ros2";
    std::string library = "binocle";
    Compression compression = Compression::Zstd;
    int compression_level = 1;                       // zstd: 1 (fast) .. 19; lz4: ignored
    uint64_t chunk_bytes = uint64_t{8} << 20;        // a chunk is closed once its records pass this
    uint64_t chunk_span_ns = 1000000000;             // ... or span this much log time (1 s)
    bool sync_chunks = true;                         // fsync after each chunk (durability)
    bool chunk_indexes = true;                       // write Chunk Index records in the summary
    bool message_indexes = true;                     // write Message Index records after each chunk
};

class Writer {
public:
    // Creates `path`; an existing file is refused (nothing is overwritten).
    Writer(const std::string &path, WriterOptions options = {});
    ~Writer(); // closes when close() was not called; errors are then lost: call close()
    Writer(const Writer &) = delete;
    Writer &operator=(const Writer &) = delete;

    uint16_t addSchema(const std::string &name, const std::string &encoding, const std::string &data);
    uint16_t addChannel(uint16_t schema_id, const std::string &topic, const std::string &message_encoding,
                        const KeyValues &metadata = {});
    void write(uint16_t channel_id, uint32_t sequence, uint64_t log_time, uint64_t publish_time, const uint8_t *data,
               size_t size);
    // A Metadata record (e.g. rosbag2's "rosbag2" record), written at close in the data section.
    void addMetadata(const std::string &name, const KeyValues &values);

    // Writes the open chunk (and fsyncs it with sync_chunks).
    void flush();
    // Writes the last chunk, Data End, the summary, the footer and the magic; closes the file.
    void close();

    // Every message written, including those of the open chunk (not on disk yet).
    const Statistics &statistics() const;
    // The messages a reader of the file recovers: those of the chunks written whole (and
    // fsync'ed with sync_chunks), in the order they were written. A write that fails is
    // cut back off the file, so this stays exact after a full disk; close() adds the last chunk.
    uint64_t durableMessageCount() const;
    uint64_t bytesWritten() const;
    const std::string &path() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// ---- Reader --------------------------------------------------------------------------------

struct ReaderOptions {
    uint64_t max_record_bytes = uint64_t{1} << 30;      // any record (or a chunk's records) larger is refused
    uint64_t max_summary_bytes = uint64_t{256} << 20;   // the summary section
    bool check_crcs = true;                             // chunk CRCs on decompression, data/summary CRCs on open
};

// Where a chunk is and what it holds, from its Chunk Index record or from a scan.
struct ChunkInfo {
    uint64_t offset = 0;           // of the Chunk record in the file
    uint64_t length = 0;           // of the whole record
    uint64_t message_start_time = 0, message_end_time = 0;
    uint64_t compressed_size = 0, uncompressed_size = 0;
    std::string compression;
};

class Reader {
public:
    // Opens `path`, checks the magic and the header, and reads the summary (or, without
    // one, scans the data section). Throws mcap::Error.
    explicit Reader(const std::string &path, ReaderOptions options = {});
    ~Reader();
    Reader(const Reader &) = delete;
    Reader &operator=(const Reader &) = delete;

    const std::string &path() const;
    const std::string &profile() const;
    const std::string &library() const;
    const std::map<uint16_t, Schema> &schemas() const;
    const std::map<uint16_t, Channel> &channels() const;
    const std::vector<ChunkInfo> &chunks() const; // in message_start_time order
    // Statistics from the summary, or counted by the scan.
    const Statistics &statistics() const;
    // True when the file was read through its summary and chunk indexes.
    bool indexed() const;
    // Why the file was scanned and where the scan stopped; empty when read by its index.
    const std::string &recoveryNote() const;
    const std::vector<std::pair<std::string, KeyValues>> &metadata() const;

    // The channel of `topic`, or null.
    const Channel *channelByTopic(const std::string &topic) const;
    const Schema *schemaOf(const Channel &channel) const;

    // Calls `visit` for each message of `channel_ids` (all when empty) whose log time is in
    // [start_ns, end_ns], chunk by chunk in time order and in log-time order within a
    // chunk. `visit` returns false to stop. Throws mcap::Error on a bad chunk.
    void readMessages(const std::function<bool(const MessageView &)> &visit, const std::vector<uint16_t> &channel_ids = {},
                      uint64_t start_ns = 0, uint64_t end_ns = UINT64_MAX) const;

    // The uncompressed records of the chunk at `chunk_index` (in chunks()), CRC checked;
    // the reader keeps the last two in memory.
    std::shared_ptr<const std::vector<uint8_t>> chunkRecords(size_t chunk_index) const;
    // The message at `record_offset` in chunk `chunk_index`'s records (as found by
    // readMessages), or, with chunk_index = SIZE_MAX, at that offset in the file.
    // The view's data stays valid while `hold` lives.
    MessageView messageAt(size_t chunk_index, int64_t record_offset, std::shared_ptr<const std::vector<uint8_t>> &hold) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// CRC-32 (ISO-HDLC, as zlib's crc32), continued from `crc` (0 to start).
uint32_t crc32(const uint8_t *data, size_t size, uint32_t crc = 0);

} // namespace binocle::mcap
