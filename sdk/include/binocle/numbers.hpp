// SPDX-License-Identifier: MIT
// The one number reader, header-only: every number Binocle reads from text (plugin
// settings, rig files, --set, command-line options, CSV cells, file headers) is read
// by these, so "010" gets one answer everywhere: an error, never 8 and never 10.
//
// The rule: decimal only. A leading zero before another digit is refused ("0640" is 416
// to yaml-cpp, strtol(.., 0) and CLI11, and 640 to others: a value that reads two ways is
// a mistake to report, not to guess). Hexadecimal ("0x10"), octal ("0o20") and binary
// ("0b10") prefixes, digit separators, surrounding spaces and trailing text are refused
// too. Reals are decimal with an optional fraction and exponent ("1.5", ".5", "1e3");
// "nan", "inf" and hexadecimal floats are refused unless a caller asks for non-finite
// values. Every refusal says what was expected in a `why` that starts with "expected".
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

namespace binocle::sdk {

namespace detail {

inline bool isDigit(char c) { return c >= '0' && c <= '9'; }

inline bool numberFail(std::string *why, std::string what) {
    if (why) *why = std::move(what);
    return false;
}

// Why a text with a radix prefix is refused, naming the decimal value where it fits:
// "0x10" -> "expected a decimal number (0x10 is hexadecimal: write 16)".
inline std::string radixWhy(std::string_view text, size_t start, const char *noun) {
    const char p = static_cast<char>(text[start + 1] | 0x20);
    const int base = p == 'x' ? 16 : p == 'o' ? 8 : 2;
    const char *name = p == 'x' ? "hexadecimal" : p == 'o' ? "octal" : "binary";
    uint64_t v = 0;
    bool fits = start + 2 < text.size() && text.size() - start - 2 <= 15; // 15 hex digits < 2^60
    for (size_t k = start + 2; fits && k < text.size(); ++k) {
        const char c = static_cast<char>(text[k] | 0x20);
        const int d = isDigit(text[k]) ? text[k] - '0' : (c >= 'a' && c <= 'f') ? c - 'a' + 10 : 99;
        if (d >= base) fits = false;
        v = v * static_cast<uint64_t>(base) + static_cast<uint64_t>(d);
    }
    std::string what = std::string("expected a decimal ") + noun + " (" + std::string(text) + " is " + name;
    if (fits) what += ": write " + std::string(text[0] == '-' ? "-" : "") + std::to_string(v);
    return what + ")";
}

// Why a leading zero is refused: "0640" -> "... (0640 reads as octal 416 elsewhere: write
// 640)"; the octal reading is named only when the digits are octal.
inline std::string leadingZeroWhy(std::string_view text, size_t start, const char *noun) {
    size_t first = start;
    while (first + 1 < text.size() && text[first] == '0' && isDigit(text[first + 1])) ++first;
    std::string digits(text.substr(first));
    size_t end = 0;
    while (end < digits.size() && isDigit(digits[end])) ++end;
    bool octal = end == text.size() - first && end <= 20;
    uint64_t v = 0;
    for (size_t k = start; octal && k < text.size(); ++k) {
        if (text[k] > '7') octal = false;
        else v = v * 8 + static_cast<uint64_t>(text[k] - '0');
    }
    const std::string sign = start > 0 && text[0] == '-' ? "-" : "";
    std::string what = std::string("expected a decimal ") + noun + " without leading zeros (" + std::string(text);
    what += octal ? " would read as octal " + sign + std::to_string(v) + " elsewhere" : " would read as octal elsewhere";
    return what + ": write " + sign + digits + ")";
}

// A radix prefix (0x, 0o, 0b in either case) at text[start]?
inline bool hasRadixPrefix(std::string_view text, size_t start) {
    if (start + 1 >= text.size() || text[start] != '0') return false;
    const char p = static_cast<char>(text[start + 1] | 0x20);
    return p == 'x' || p == 'o' || p == 'b';
}

} // namespace detail

// A decimal integer: an optional sign and digits, nothing else, within 64 bits.
// Refused: "0640" (a leading zero reads as octal elsewhere), "0x10", "1e3", "12px",
// " 3", "". On failure returns false and says why in `why`.
inline bool parseDecimalInteger(std::string_view text, int64_t &out, std::string *why = nullptr) {
    size_t i = 0;
    const bool negative = !text.empty() && text[0] == '-';
    if (!text.empty() && (text[0] == '-' || text[0] == '+')) i = 1;
    if (i == text.size()) return detail::numberFail(why, "expected a decimal integer");
    if (detail::hasRadixPrefix(text, i)) return detail::numberFail(why, detail::radixWhy(text, i, "integer"));
    for (size_t k = i; k < text.size(); ++k)
        if (!detail::isDigit(text[k])) return detail::numberFail(why, "expected a decimal integer");
    if (text[i] == '0' && text.size() - i > 1) return detail::numberFail(why, detail::leadingZeroWhy(text, i, "integer"));
    // Accumulate as a negative number: INT64_MIN has no positive counterpart.
    int64_t v = 0;
    for (size_t k = i; k < text.size(); ++k) {
        const int d = text[k] - '0';
        if (v < (INT64_MIN + d) / 10) return detail::numberFail(why, "expected an integer within 64 bits");
        v = v * 10 - d;
    }
    if (!negative) {
        if (v == INT64_MIN) return detail::numberFail(why, "expected an integer within 64 bits");
        v = -v;
    }
    out = v;
    return true;
}

// A decimal real number: [sign] digits [. digits] [e [sign] digits], or ".5", with no
// leading zero before another digit ("010", "010.5"; "0.5" and "0e3" are fine). Refused:
// hexadecimal floats, "nan", "inf" (unless allowNonFinite: then also ".inf", "-.inf",
// ".nan" as YAML writes them), values that overflow a double (1e999) and trailing text.
inline bool parseDecimalReal(std::string_view text, double &out, std::string *why = nullptr,
                             bool allowNonFinite = false) {
    if (allowNonFinite) {
        std::string lower(text);
        for (char &c : lower)
            if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
        if (lower == ".inf" || lower == "+.inf" || lower == "inf" || lower == "+inf") {
            out = HUGE_VAL;
            return true;
        }
        if (lower == "-.inf" || lower == "-inf") {
            out = -HUGE_VAL;
            return true;
        }
        if (lower == ".nan" || lower == "nan") {
            out = std::nan("");
            return true;
        }
    }
    const char *plain = allowNonFinite ? "expected a decimal number (or .inf, .nan)" : "expected a decimal number";
    // Grammar first, so that strtod's extras (hex floats, "inf", "nan", leading spaces)
    // never get through.
    size_t i = 0;
    if (i < text.size() && (text[i] == '-' || text[i] == '+')) ++i;
    const size_t start = i;
    if (detail::hasRadixPrefix(text, start)) return detail::numberFail(why, detail::radixWhy(text, start, "number"));
    size_t digits = 0;
    while (i < text.size() && detail::isDigit(text[i])) ++i, ++digits;
    const size_t wholeDigits = digits;
    if (i < text.size() && text[i] == '.') {
        ++i;
        while (i < text.size() && detail::isDigit(text[i])) ++i, ++digits;
    }
    if (digits == 0) return detail::numberFail(why, plain);
    if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
        ++i;
        if (i < text.size() && (text[i] == '-' || text[i] == '+')) ++i;
        size_t exp = 0;
        while (i < text.size() && detail::isDigit(text[i])) ++i, ++exp;
        if (exp == 0) return detail::numberFail(why, "expected a decimal number (the exponent has no digits)");
    }
    if (i != text.size()) return detail::numberFail(why, plain);
    if (wholeDigits > 1 && text[start] == '0') return detail::numberFail(why, detail::leadingZeroWhy(text, start, "number"));
    const std::string copy(text);
    errno = 0;
    char *end = nullptr;
    const double v = std::strtod(copy.c_str(), &end);
    if (end != copy.c_str() + copy.size()) return detail::numberFail(why, plain);
    if (errno == ERANGE && std::isinf(v))
        return detail::numberFail(why, "expected a number within the range of a double (about 1.8e308)");
    out = v; // underflow to 0 or a denormal is fine
    return true;
}

// A boolean as YAML 1.1 (and yaml-cpp) writes it: true/false, yes/no, on/off, y/n, each
// all lower case, all upper case or capitalised ("True"). Anything else, "1" and "0"
// included, is refused.
inline bool parseBoolean(std::string_view text, bool &out) {
    static const char *const kWords[][2] = {{"true", "false"}, {"yes", "no"}, {"on", "off"}, {"y", "n"}};
    auto same = [&](const char *word) {
        const std::string_view w(word);
        if (w.size() != text.size()) return false;
        bool lower = true, upper = true, title = true;
        for (size_t k = 0; k < w.size(); ++k) {
            const char c = text[k], up = static_cast<char>(w[k] - 'a' + 'A');
            lower = lower && c == w[k];
            upper = upper && c == up;
            title = title && c == (k == 0 ? up : w[k]);
        }
        return lower || upper || title;
    };
    for (const auto &pair : kWords)
        for (int v = 0; v < 2; ++v)
            if (same(pair[v])) {
                out = v == 0;
                return true;
            }
    return false;
}

// What a reader's `why` adds to "expected a decimal integer", to follow a caller's own
// words for what it expects: "expected a decimal integer without leading zeros (010 ...)"
// -> ", without leading zeros (010 ...)"; "expected a decimal integer" -> "".
inline std::string numberWhyDetail(const std::string &why) {
    for (const char *head : {"expected a decimal integer", "expected a decimal number", "expected an integer",
                             "expected a number"}) {
        const std::string h(head);
        if (why.compare(0, h.size(), h) != 0) continue;
        const std::string rest = why.substr(h.size());
        if (rest.empty() || rest[0] == '(' || rest.compare(0, 2, " (") == 0) return rest;
        return "," + rest;
    }
    return why.empty() ? "" : " (" + why + ")";
}

} // namespace binocle::sdk
