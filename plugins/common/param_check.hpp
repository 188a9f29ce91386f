// SPDX-License-Identifier: MIT
// Checks a plugin's settings against its own binocle_param_desc table (min, max, odd,
// multiple of, choices), so that a plugin refuses bad values with a clear message even
// when its host did not validate them.
//
// Header-only; plugins/common has no CMakeLists.txt on purpose (every folder with one
// is built as a plugin).
#pragma once

#include <binocle/plugin.hpp>

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

namespace binocle::plugins {

inline std::string formatNumber(double v) {
    std::ostringstream s;
    s << v; // 1500, 0.5, -90: no trailing zeros
    return s.str();
}

// Throws Error(BINOCLE_ERR_INVALID_ARGUMENT, "<plugin>: <key> = <value>: expected <what>").
inline void checkParameters(const sdk::Params &params, const std::vector<binocle_param_desc> &table,
                            const std::string &plugin) {
    for (const binocle_param_desc &d : table) {
        const std::string key = d.name;
        auto refuse = [&](const std::string &value, const std::string &expected) {
            throw sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT,
                             plugin + ": " + key + " = " + value + ": expected " + expected);
        };
        if (d.type == BINOCLE_PARAM_INT || d.type == BINOCLE_PARAM_DOUBLE) {
            const double v = params.real(key);
            const std::string text = formatNumber(v);
            if (!std::isfinite(v)) refuse(text, "a finite number");
            if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) && v < d.min) refuse(text, "a value >= " + formatNumber(d.min));
            if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) && v > d.max) refuse(text, "a value <= " + formatNumber(d.max));
            if (d.type == BINOCLE_PARAM_INT) {
                const int64_t i = params.integer(key);
                if (i < INT32_MIN || i > INT32_MAX) refuse(text, "a 32-bit integer");
                if ((d.flags & BINOCLE_PARAM_FLAG_ODD) && i % 2 == 0) refuse(text, "an odd number");
                if (d.multiple_of > 0 && i % d.multiple_of != 0)
                    refuse(text, "a multiple of " + std::to_string(d.multiple_of));
            }
        } else if (d.type == BINOCLE_PARAM_ENUM && d.choices) {
            const std::string v = params.string(key);
            const std::string choices = std::string("|") + d.choices + "|";
            if (v.empty() || v.find('|') != std::string::npos || choices.find("|" + v + "|") == std::string::npos)
                refuse("'" + v + "'", std::string("one of ") + d.choices);
        }
    }
}

} // namespace binocle::plugins
