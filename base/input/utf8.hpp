// SPDX-License-Identifier: MIT
// Untrusted text on its way into the files Binocle writes: UTF-8 validity (JSON, YAML)
// and XML escaping. (The UTF-8 sequence rule and printable excerpts for messages are
// the SDK's: binocle/text.hpp.)
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace binocle::input {

// True when `text` is well-formed UTF-8 (no overlong forms, surrogates or code points
// above U+10FFFF). Otherwise `badOffset` receives the offset of the first bad byte.
bool isValidUtf8(std::string_view text, size_t *badOffset = nullptr);

// The text with every ill-formed byte replaced by U+FFFD: safe to put in JSON.
std::string sanitizeUtf8(std::string_view text);

// `s` with &, <, >, " and ' escaped, and the control characters XML 1.0 refuses (all
// below 0x20 but tab, newline and carriage return) made spaces: for XML (JUnit, SVG) and
// HTML text and attribute values.
std::string xmlEscape(std::string_view s);

} // namespace binocle::input
