// SPDX-License-Identifier: MIT
// The recording format: written by `binocle record`, read by the `replay` source, and
// usable by any plugin or tool (header-only, the C++ standard library and POSIX only).
//
// A recording is a folder:
//   frames.csv        the index: the header below, then one row per pair, in order
//                     sequence,timestamp_left_ns,timestamp_right_ns,left,right
//   left/NNNNNN.png   right/NNNNNN.png: lossless PNG (grey or colour, 8 or 16 bit);
//                     NNNNNN is the source's sequence number, at least six digits
//   calibration.yml   the rig's calibration (OpenCV FileStorage YAML), when it has one
//   rig.yaml          the rig as it was resolved for the recording
//
// What a crash at any moment leaves (the writer's rules, kept by `binocle record`):
//   1. an image is written to a temporary file in its folder, fsync'ed, then renamed;
//   2. before a row names an image, the image's folder is fsync'ed (the rename is durable);
//   3. rows are appended to frames.csv in batches, each batch fsync'ed.
// So every complete row names images that are whole on disk. A reader ignores a last row
// that is incomplete (the writer stopped while writing it) and rows at the end whose
// images are missing, and refuses every other bad row, naming the file and line.
#pragma once

#include <binocle/plugin.hpp>
#include <binocle/text.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <unistd.h>
#include <vector>

namespace binocle::recording {

inline constexpr const char *kIndexFile = "frames.csv";
inline constexpr const char *kCalibrationFile = "calibration.yml";
inline constexpr const char *kRigFile = "rig.yaml";
inline constexpr const char *kSideFolders[2] = {"left", "right"};
inline constexpr const char *kIndexColumns[5] = {"sequence", "timestamp_left_ns", "timestamp_right_ns", "left", "right"};
inline constexpr const char *kIndexHeader = "sequence,timestamp_left_ns,timestamp_right_ns,left,right\n";

// One pair of the index. Paths are relative to the recording folder.
struct Row {
    int64_t sequence = 0;
    int64_t timestamp_left_ns = 0, timestamp_right_ns = 0;
    std::string left, right;
    int line = 0; // in frames.csv, when read
};

// "left/000042.png" for side 0 (left) or 1 (right).
inline std::string imagePath(int side, uint64_t sequence) {
    char name[40];
    std::snprintf(name, sizeof name, "%s/%06llu.png", kSideFolders[side != 0], static_cast<unsigned long long>(sequence));
    return name;
}

// The row of a pair written under the standard image names.
inline Row rowFor(uint64_t sequence, int64_t timestampLeftNs, int64_t timestampRightNs) {
    Row r;
    r.sequence = static_cast<int64_t>(sequence);
    r.timestamp_left_ns = timestampLeftNs;
    r.timestamp_right_ns = timestampRightNs;
    r.left = imagePath(0, sequence);
    r.right = imagePath(1, sequence);
    return r;
}

// The line of frames.csv for `r`, with its newline.
inline std::string formatRow(const Row &r) {
    return std::to_string(r.sequence) + "," + std::to_string(r.timestamp_left_ns) + "," +
           std::to_string(r.timestamp_right_ns) + "," + r.left + "," + r.right + "\n";
}

struct Index {
    std::vector<Row> rows;
    std::string dropped_last; // why the last line was ignored; empty when it was not
};

namespace detail {

inline std::string trimmed(std::string_view s) {
    const size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
    return b == std::string_view::npos ? std::string() : std::string(s.substr(b, e - b + 1));
}

inline std::vector<std::string> splitFields(std::string_view line) {
    std::vector<std::string> fields;
    for (size_t start = 0;;) {
        const size_t comma = line.find(',', start);
        fields.push_back(trimmed(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
        if (comma == std::string_view::npos) return fields;
        start = comma + 1;
    }
}

[[noreturn]] inline void refuse(const std::string &what) { throw sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT, what); }


} // namespace detail

// A file of the recording in `folder` as it resolves (symbolic links followed), when that
// lies outside the folder: a `left/` planted as a link to elsewhere would have replay read
// whatever it points at. Empty when the file stays inside (or cannot be resolved: the
// reader's own check then says it does not exist).
inline std::string outsideOf(const std::filesystem::path &folder, const std::filesystem::path &file) {
    std::error_code ec;
    const std::filesystem::path base = std::filesystem::canonical(folder, ec);
    if (ec) return {};
    const std::filesystem::path real = std::filesystem::weakly_canonical(file, ec);
    if (ec) return {};
    const auto rel = real.lexically_relative(base);
    if (!rel.empty() && *rel.begin() != "..") return {};
    return real.string();
}

// Reads the text of frames.csv; `origin` names it in messages. The header may order
// the columns as it likes (each exactly once); blank lines and a UTF-8 byte order mark are skipped. Image paths must
// stay inside the recording folder. Throws sdk::Error (BINOCLE_ERR_INVALID_ARGUMENT)
// "<origin>:<line>: ..." for a bad header or a bad row other than the last.
inline Index parseIndex(std::string_view text, const std::string &origin) {
    struct Line {
        std::string_view text;
        int number;
    };
    std::vector<Line> lines;
    int number = 0;
    // A UTF-8 byte order mark (spreadsheets write one) is not part of the first column's name.
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
    for (size_t start = 0; start < text.size();) {
        size_t end = text.find('\n', start);
        if (end == std::string_view::npos) end = text.size();
        std::string_view l = text.substr(start, end - start);
        if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
        ++number;
        if (l.find_first_not_of(" \t") != std::string_view::npos) lines.push_back({l, number});
        start = end + 1;
    }
    if (lines.empty()) detail::refuse("'" + origin + "' is empty; expected a header line");
    const std::string at0 = origin + ":" + std::to_string(lines.front().number);
    const std::vector<std::string> header = detail::splitFields(lines.front().text);
    size_t column[5];
    for (int c = 0; c < 5; ++c) {
        const auto it = std::find(header.begin(), header.end(), kIndexColumns[c]);
        if (it == header.end())
            detail::refuse(at0 + ": header '" + sdk::printable(lines.front().text) + "' has no column '" + kIndexColumns[c] +
                           "'; expected sequence,timestamp_left_ns,timestamp_right_ns,left,right");
        if (std::find(it + 1, header.end(), kIndexColumns[c]) != header.end())
            detail::refuse(at0 + ": header names column '" + kIndexColumns[c] + "' twice");
        column[c] = static_cast<size_t>(it - header.begin());
    }
    Index index;
    for (size_t i = 1; i < lines.size(); ++i) {
        const Line &l = lines[i];
        const std::vector<std::string> fields = detail::splitFields(l.text);
        Row r;
        r.line = l.number;
        std::string problem, why;
        bool escapes = false; // a path leading out of the folder is never a cut-short line
        if (fields.size() != header.size()) {
            problem = std::to_string(fields.size()) + " fields; expected " + std::to_string(header.size());
        } else if (!sdk::parseDecimalInteger(fields[column[0]], r.sequence, &why) || r.sequence < 0) {
            problem = "sequence '" + sdk::printable(fields[column[0]], 30) + "': " +
                      (why.empty() ? "expected an integer >= 0" : why);
        } else if (!sdk::parseDecimalInteger(fields[column[1]], r.timestamp_left_ns, &why) ||
                   !sdk::parseDecimalInteger(fields[column[2]], r.timestamp_right_ns, &why)) {
            problem = "time stamps must be decimal integers of nanoseconds: " + why;
        } else {
            r.left = fields[column[3]];
            r.right = fields[column[4]];
            for (const std::string *path : {&r.left, &r.right})
                if (problem.empty() && !sdk::isConfinedRelativePath(*path, &why)) {
                    problem = "image path '" + sdk::printable(*path) + "': " + why +
                              " (expected a path inside the recording folder, e.g. left/000000.png)";
                    escapes = !path->empty();
                }
        }
        if (!problem.empty()) {
            if (i + 1 == lines.size() && !escapes) { // the writer stopped while writing this line
                index.dropped_last = origin + ":" + std::to_string(l.number) + " is incomplete (" + problem + ")";
                break;
            }
            detail::refuse(origin + ":" + std::to_string(l.number) + ": '" + sdk::printable(l.text) + "': " + problem);
        }
        index.rows.push_back(std::move(r));
    }
    return index;
}

// Writes all of `bytes` to `fd` and fsyncs it (rule 3); throws sdk::Error
// (BINOCLE_ERR_IO) naming `path`.
inline void appendDurably(int fd, std::string_view bytes, const std::string &path) {
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        // write() returning 0 sets no errno: name what it means rather than a stale errno.
        if (n <= 0)
            throw sdk::Error(BINOCLE_ERR_IO, "cannot write " + path + ": " +
                                                 (n < 0 ? std::strerror(errno) : "no byte written (is the disk full?)"));
        done += static_cast<size_t>(n);
    }
    if (::fsync(fd) != 0) throw sdk::Error(BINOCLE_ERR_IO, "cannot write " + path + ": fsync failed: " + std::strerror(errno));
}

// Rules 2 and 3 for a batch: the image folders (open descriptors of left/ and right/)
// are fsync'ed, then the rows are appended to frames.csv and fsync'ed.
inline void appendRowsDurably(int indexFd, const int sideFolderFds[2], const std::vector<Row> &rows,
                              const std::string &recordingDir) {
    for (int i = 0; i < 2; ++i)
        if (::fsync(sideFolderFds[i]) != 0)
            throw sdk::Error(BINOCLE_ERR_IO, "cannot write " + recordingDir + "/" + kSideFolders[i] +
                                                 ": fsync failed: " + std::strerror(errno));
    std::string lines;
    for (const Row &r : rows) lines += formatRow(r);
    appendDurably(indexFd, lines, recordingDir + "/" + kIndexFile);
}

} // namespace binocle::recording
