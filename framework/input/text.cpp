// SPDX-License-Identifier: MIT
// UTF-8 validity, printable excerpts, confined paths and safe names.
#include "input/text.hpp"

#include <cstdio>
#include <cstdint>

namespace binocle::input {

namespace {

// Length of the well-formed UTF-8 sequence at text[i], 0 when ill-formed (RFC 3629).
size_t sequenceLength(std::string_view text, size_t i) {
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

} // namespace

bool isValidUtf8(std::string_view text, size_t *badOffset) {
    for (size_t i = 0; i < text.size();) {
        const size_t n = sequenceLength(text, i);
        if (n == 0) {
            if (badOffset) *badOffset = i;
            return false;
        }
        i += n;
    }
    return true;
}

std::string sanitizeUtf8(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (size_t i = 0; i < text.size();) {
        const size_t n = sequenceLength(text, i);
        if (n == 0) {
            out += "\xEF\xBF\xBD";
            ++i;
        } else {
            out.append(text.substr(i, n));
            i += n;
        }
    }
    return out;
}

std::string printable(std::string_view text, size_t maxChars) {
    std::string out;
    size_t chars = 0, i = 0;
    for (; i < text.size() && chars < maxChars; ++chars) {
        const size_t n = sequenceLength(text, i);
        const auto c = static_cast<uint8_t>(text[i]);
        char buf[8];
        if (n == 0 || c < 0x20 || c == 0x7F) {
            if (c == '\n') out += "\\n";
            else if (c == '\t') out += "\\t";
            else {
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

bool isConfinedRelativePath(std::string_view path, std::string *why) {
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

bool isSafeName(std::string_view name, std::string *why) {
    auto fail = [&](const char *what) {
        if (why) *why = what;
        return false;
    };
    if (name.empty()) return fail("empty name");
    if (name.size() > 100) return fail("longer than 100 characters");
    for (char c : name) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                        c == '_' || c == '-';
        if (!ok) return fail("expected letters, digits, '.', '_' or '-' only");
    }
    if (name.front() == '.') return fail("starts with '.'");
    return true;
}

} // namespace binocle::input
