// SPDX-License-Identifier: MIT
// Integers within a range: a decimal integer read from untrusted text and checked
// against [min, max] in one call, and whether a double fits an integer type. The reading
// itself is the SDK's (binocle/numbers.hpp: sdk::parseDecimalInteger, parseDecimalReal),
// which callers without a range use directly.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace binocle::input {

// A decimal integer (sdk::parseDecimalInteger: "0640", "0x10", "1e3", "12px", " 3" and
// "" refused) within [min, max]. On failure returns false and says why in `why` (e.g.
// "expected a decimal integer", "expected an integer <= 16").
bool parseInteger(std::string_view text, int64_t &out, std::string *why, int64_t min, int64_t max);

// A finite double that fits `int` (or int64) when rounded toward zero: false for NaN,
// inf and out-of-range values, so that no cast is undefined.
bool fitsInt(double v);
bool fitsInt64(double v);

} // namespace binocle::input
