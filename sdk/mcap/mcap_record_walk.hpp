// SPDX-License-Identifier: MIT
// The one walk over MCAP records (internal to libbinocle_mcap), used by the reader for
// the summary section, a chunk's records and, when it recovers a file, the data section:
// each record's opcode, offset and length read by a span (the records in memory, or in
// the file as the walk goes), then handed to a visitor, which asks the span for its
// fields. As the MCAP project's C++ library reads records by type, the visitor switches
// on the opcode and reads each record's typed fields (mcap_records.hpp).
#pragma once

#include "mcap_bytes.hpp"

#include <cstdint>
#include <string>

namespace binocle::mcap::detail {

constexpr uint64_t kRecordHead = 9; // opcode + length

// One record a walk met: its opcode, the offset of its opcode (in the file, or in a
// chunk's records) and the length of its fields.
struct RecordAt {
    uint8_t op = 0;
    uint64_t offset = 0, length = 0;
    bool is(Opcode o) const { return op == static_cast<uint8_t>(o); }
};

// Records in memory: the summary section (base: its offset in the file) or a chunk's
// records (base 0). A record whose length runs past the end throws, naming it by
// `where` + its offset and the fields `lengthName` and `recordName`.
class MemoryRecords {
public:
    MemoryRecords(const uint8_t *data, size_t size, uint64_t base, std::string where, const char *lengthName,
                  const char *recordName)
        : data_(data), size_(size), base_(base), where_(std::move(where)), lengthName_(lengthName),
          recordName_(recordName) {}

    // The record at `offset`; false at the end.
    bool head(uint64_t offset, RecordAt &r) const {
        const size_t i = static_cast<size_t>(offset - base_);
        if (i >= size_) return false;
        Cursor h(data_ + i, size_ - i, where(offset));
        r.op = h.u8("opcode");
        r.length = h.u64(lengthName_);
        h.run(r.length, recordName_);
        r.offset = offset;
        return true;
    }
    Cursor fields(const RecordAt &r) const {
        return Cursor(data_ + static_cast<size_t>(r.offset - base_) + kRecordHead, static_cast<size_t>(r.length),
                      where(r.offset));
    }
    std::string where(uint64_t offset) const { return where_ + std::to_string(offset); }

private:
    const uint8_t *data_;
    size_t size_;
    uint64_t base_;
    std::string where_;
    const char *lengthName_, *recordName_;
};

// The walk: the span's records from `offset` on, each handed to visit(record), until the
// span has no more or visit returns false. A span's head(offset, record) reads one
// record's opcode and length (false: the records end there).
template <class Span, class Visit>
void walkRecords(Span &span, uint64_t offset, Visit &&visit) {
    RecordAt r;
    while (span.head(offset, r) && visit(r)) offset += kRecordHead + r.length;
}

} // namespace binocle::mcap::detail
