// SPDX-License-Identifier: MIT
// Integers within a range, on the SDK's number reader (binocle/numbers.hpp).
#include "input/integer_range.hpp"

#include <binocle/numbers.hpp>

#include <climits>
#include <cmath>
#include <string>

namespace binocle::input {

namespace {

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

bool fitsInt(double v) { return std::isfinite(v) && v > static_cast<double>(INT_MIN) - 1.0 && v < static_cast<double>(INT_MAX) + 1.0; }

bool fitsInt64(double v) {
    // 2^63 is exactly representable; every double below it (and >= -2^63) fits.
    return std::isfinite(v) && v >= -9223372036854775808.0 && v < 9223372036854775808.0;
}

} // namespace binocle::input
