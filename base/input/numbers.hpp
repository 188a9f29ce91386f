// SPDX-License-Identifier: MIT
// The one strict reader of numbers in untrusted text (YAML values, --set, command-line
// options, CSV cells, calibration files): decimal only, whole text, range-checked before
// any cast. The rule itself lives in the SDK (binocle/numbers.hpp) so plugins share it.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace binocle::input {

// A decimal integer: an optional sign and digits, nothing else. Refused: "0640" (a
// leading zero reads as octal elsewhere), "0x10", "1e3", "12px", " 3", "" and anything
// outside [min, max]. On failure returns false and says why in `why` (e.g.
// "expected a decimal integer", "expected an integer <= 2147483647").
bool parseInteger(std::string_view text, int64_t &out, std::string *why = nullptr, int64_t min = INT64_MIN,
                  int64_t max = INT64_MAX);

// A decimal real number: [sign] digits [. digits] [e [sign] digits], or ".5". Refused:
// a leading zero before another digit ("010", "010.5"; "0.5" is fine), hexadecimal floats, "nan", "inf" (unless allowNonFinite: then also ".inf", "-.inf",
// ".nan" as YAML writes them), values that overflow a double (1e999) and trailing text.
bool parseReal(std::string_view text, double &out, std::string *why = nullptr, bool allowNonFinite = false);

// A finite double that fits `int` (or int64) when rounded toward zero: false for NaN,
// inf and out-of-range values, so that no cast is undefined.
bool fitsInt(double v);
bool fitsInt64(double v);

} // namespace binocle::input
