// SPDX-License-Identifier: MIT
// UTF-8 validity (on the SDK's sequence rule, binocle/text.hpp) and XML escaping.
#include "input/utf8.hpp"

#include <binocle/text.hpp>

namespace binocle::input {

bool isValidUtf8(std::string_view text, size_t *badOffset) {
    for (size_t i = 0; i < text.size();) {
        const size_t n = sdk::utf8SequenceLength(text, i);
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
        const size_t n = sdk::utf8SequenceLength(text, i);
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

std::string xmlEscape(std::string_view s) {
    std::string out;
    for (char c : s) {
        switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        case '\'': out += "&apos;"; break;
        default:
            if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t' && c != '\r') out += ' ';
            else out += c;
        }
    }
    return out;
}

} // namespace binocle::input
