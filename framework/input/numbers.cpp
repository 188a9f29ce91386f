// SPDX-License-Identifier: MIT
// The one strict reader of numbers in untrusted text.
#include "input/numbers.hpp"

#include <binocle/text.hpp>

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <string>

namespace binocle::input {

namespace {

bool isDigit(char c) { return c >= '0' && c <= '9'; }

bool fail(std::string *why, const std::string &text) {
    if (why) *why = text;
    return false;
}

} // namespace

bool parseInteger(std::string_view text, int64_t &out, std::string *why, int64_t min, int64_t max) {
    int64_t v = 0;
    if (!sdk::parseDecimalInteger(text, v, why)) return false;
    if (v < min) return fail(why, "expected an integer >= " + std::to_string(min));
    if (v > max) return fail(why, "expected an integer <= " + std::to_string(max));
    out = v;
    return true;
}

bool parseReal(std::string_view text, double &out, std::string *why, bool allowNonFinite) {
    if (allowNonFinite) {
        std::string lower(text);
        for (char &c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
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
    // Grammar first, so that strtod's extras (hex floats, "inf", "nan", leading spaces)
    // never get through.
    size_t i = 0;
    if (i < text.size() && (text[i] == '-' || text[i] == '+')) ++i;
    size_t digits = 0;
    while (i < text.size() && isDigit(text[i])) ++i, ++digits;
    if (i < text.size() && text[i] == '.') {
        ++i;
        while (i < text.size() && isDigit(text[i])) ++i, ++digits;
    }
    if (digits == 0) return fail(why, allowNonFinite ? "expected a decimal number (or .inf, .nan)" : "expected a decimal number");
    if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
        ++i;
        if (i < text.size() && (text[i] == '-' || text[i] == '+')) ++i;
        size_t exp = 0;
        while (i < text.size() && isDigit(text[i])) ++i, ++exp;
        if (exp == 0) return fail(why, "expected a decimal number (the exponent has no digits)");
    }
    if (i != text.size()) return fail(why, "expected a decimal number");
    const std::string copy(text);
    errno = 0;
    char *end = nullptr;
    const double v = std::strtod(copy.c_str(), &end);
    if (end != copy.c_str() + copy.size()) return fail(why, "expected a decimal number");
    if (errno == ERANGE && std::isinf(v)) return fail(why, "expected a number within the range of a double (about 1.8e308)");
    out = v; // underflow to 0 or a denormal is fine
    return true;
}

bool fitsInt(double v) { return std::isfinite(v) && v > static_cast<double>(INT_MIN) - 1.0 && v < static_cast<double>(INT_MAX) + 1.0; }

bool fitsInt64(double v) {
    // 2^63 is exactly representable; every double below it (and >= -2^63) fits.
    return std::isfinite(v) && v >= -9223372036854775808.0 && v < 9223372036854775808.0;
}

} // namespace binocle::input
