// SPDX-License-Identifier: MIT
// Strict readers of untrusted text, header-only: numbers (binocle/numbers.hpp), confined
// relative paths and printable excerpts for messages. Binocle's own readers use these too, so a
// plugin that reads files of its own refuses what Binocle refuses, in the same words.
#pragma once

#include <binocle/numbers.hpp>

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace binocle::sdk {

// Length of the well-formed UTF-8 sequence at text[i] (1..4), 0 when it is ill-formed
// (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF).
inline size_t utf8SequenceLength(std::string_view text, size_t i) {
    const auto byte = [&](size_t k) { return static_cast<uint8_t>(text[k]); };
    const uint8_t c = byte(i);
    if (c < 0x80) return 1;
    size_t n = 0;
    uint8_t lo = 0x80, hi = 0xBF; // allowed range of the second byte
    if (c >= 0xC2 && c <= 0xDF) n = 2;
    else if (c == 0xE0) n = 3, lo = 0xA0;
    else if (c >= 0xE1 && c <= 0xEC) n = 3;
    else if (c == 0xED) n = 3, hi = 0x9F; // no surrogates
    else if (c >= 0xEE && c <= 0xEF) n = 3;
    else if (c == 0xF0) n = 4, lo = 0x90;
    else if (c >= 0xF1 && c <= 0xF3) n = 4;
    else if (c == 0xF4) n = 4, hi = 0x8F; // <= U+10FFFF
    else return 0;
    if (i + n > text.size()) return 0;
    if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
    for (size_t k = 2; k < n; ++k)
        if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
    return n;
}

// `text` as it may appear in a message: control characters and bytes that are not
// UTF-8 escaped (\n, \t, \xFF), cut after `maxChars` characters with "... (N bytes)".
inline std::string printable(std::string_view text, size_t maxChars = 80) {
    std::string out;
    size_t chars = 0, i = 0;
    for (; i < text.size() && chars < maxChars; ++chars) {
        const size_t n = utf8SequenceLength(text, i);
        const auto c = static_cast<uint8_t>(text[i]);
        if (n == 0 || c < 0x20 || c == 0x7F) {
            if (c == '\n') {
                out += "\\n";
            } else if (c == '\t') {
                out += "\\t";
            } else {
                char buf[8];
                std::snprintf(buf, sizeof buf, "\\x%02X", c);
                out += buf;
            }
            ++i;
        } else {
            out.append(text.substr(i, n));
            i += n;
        }
    }
    if (i < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
    return out;
}

// What a file that is not a regular file is, for a refusal: "a FIFO", "a character
// device" (/dev/zero), "a folder", ... from its st_mode.
inline std::string fileTypeName(unsigned mode) {
    switch (mode & 0170000u) { // S_IFMT
    case 0010000u: return "a FIFO";
    case 0020000u: return "a character device";
    case 0040000u: return "a folder";
    case 0060000u: return "a block device";
    case 0100000u: return "a regular file";
    case 0120000u: return "a symbolic link";
    case 0140000u: return "a socket";
    default: return "not a file";
    }
}

// A relative path that stays inside the folder it is relative to: not empty, not
// absolute, no ".." component, no NUL. "left/000001.png" yes; "../x", "/etc/passwd",
// "a/../../b" no. `why` says what is wrong.
inline bool isConfinedRelativePath(std::string_view path, std::string *why = nullptr) {
    auto fail = [&](const char *what) {
        if (why) *why = what;
        return false;
    };
    if (path.empty()) return fail("empty path");
    if (path.find('\0') != std::string_view::npos) return fail("the path holds a NUL byte");
    if (path.front() == '/') return fail("absolute path; expected a path relative to the folder");
    size_t start = 0;
    while (start <= path.size()) {
        size_t end = path.find('/', start);
        if (end == std::string_view::npos) end = path.size();
        if (path.substr(start, end - start) == "..") return fail("'..' leads out of the folder");
        start = end + 1;
    }
    return true;
}

} // namespace binocle::sdk
