// SPDX-License-Identifier: MIT
// Names from untrusted input that become JSON text or file names: UTF-8 validity and
// confinement of paths to a folder.
#pragma once

#include <binocle/text.hpp>

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace binocle::input {

// True when `text` is well-formed UTF-8 (no overlong forms, surrogates or code points
// above U+10FFFF). Otherwise `badOffset` receives the offset of the first bad byte.
bool isValidUtf8(std::string_view text, size_t *badOffset = nullptr);

// The text with every ill-formed byte replaced by U+FFFD: safe to put in JSON.
std::string sanitizeUtf8(std::string_view text);

// The text for an error message: ill-formed bytes as \xNN, control characters escaped,
// cut after `maxChars` characters with "... (N bytes)".
using sdk::printable; // sdk/include/binocle/text.hpp, shared with plugins

// A relative path that stays inside the folder it is relative to: not empty, not
// absolute, no ".." component, no NUL. "left/000001.png" yes; "../x", "/etc/passwd",
// "a/../../b" no. `why` says what is wrong.
using sdk::isConfinedRelativePath;

// A name usable as one file-name component: 1..100 characters of [A-Za-z0-9._-], not
// starting with '.' ("1", "e1-b150_f8" yes; "../x", "/x", ".", "a b" no).
bool isSafeName(std::string_view name, std::string *why = nullptr);

// The candidate closest to `word` by edit distance (ties: the longer common prefix),
// or "" when none is close: the "did you mean" of every message about a name.
std::string nearestWord(const std::string &word, const std::vector<std::string> &candidates);

// `s` with &, <, >, " and ' escaped, and the control characters XML 1.0 refuses (all
// below 0x20 but tab, newline and carriage return) made spaces: for XML (JUnit, SVG) and
// HTML text and attribute values.
std::string xmlEscape(std::string_view s);

} // namespace binocle::input
