// SPDX-License-Identifier: MIT
// Checks of a plugin's settings table (names, types, defaults), apart from loading: the
// settings checker's home in the host.
#include "host/plugin_host.hpp"
#include "host/plugin_name.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

namespace binocle {

// ---- Settings tables --------------------------------------------------------------------

namespace {

std::string formatNumber(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

// Why `text` is not a valid value of setting `d`, or "" when it is. The same rules as the
// rig validation (config/), applied to the plugin's own default.
std::string defaultProblem(const binocle_param_desc &d, const std::string &text) {
    auto range = [&](double v) -> std::string {
        if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) && v < d.min) return "is below its min " + formatNumber(d.min);
        if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) && v > d.max) return "is above its max " + formatNumber(d.max);
        return "";
    };
    switch (d.type) {
    case BINOCLE_PARAM_BOOL: {
        static const char *words[] = {"true", "false", "True", "False", "TRUE", "FALSE", "yes", "no", "on", "off"};
        for (const char *w : words)
            if (text == w) return "";
        return "is not a boolean (true or false)";
    }
    case BINOCLE_PARAM_INT: {
        char *end = nullptr;
        errno = 0;
        const long long v = std::strtoll(text.c_str(), &end, 0);
        if (text.empty() || errno || *end) return "is not an integer";
        if (std::string r = range(static_cast<double>(v)); !r.empty()) return r;
        if ((d.flags & BINOCLE_PARAM_FLAG_ODD) && v % 2 == 0) return "is not odd";
        if (d.multiple_of > 0 && v % d.multiple_of != 0) return "is not a multiple of " + std::to_string(d.multiple_of);
        return "";
    }
    case BINOCLE_PARAM_DOUBLE: {
        char *end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || *end) return "is not a number";
        if (!std::isfinite(v)) return "is not finite";
        return range(v);
    }
    case BINOCLE_PARAM_ENUM: {
        std::stringstream ss(d.choices ? d.choices : "");
        for (std::string c; std::getline(ss, c, '|');)
            if (c == text) return "";
        return std::string("is not one of its choices '") + (d.choices ? d.choices : "") + "'";
    }
    default: return ""; // strings, paths, YAML and lists: any text
    }
}

} // namespace

std::string settingsTableProblem(const binocle_param_desc *params, int32_t count) {
    if (count < 0 || count > 1000 || (count > 0 && !params))
        return "a garbage settings table (count " + std::to_string(count) + ")";
    std::map<std::string, int32_t> seen;
    for (int32_t i = 0; i < count; ++i) {
        const auto &d = params[i];
        const std::string at = "setting #" + std::to_string(i) + " '" + (d.name ? d.name : "(null)") + "'";
        if (!validName(d.name)) return at + ": invalid name (expected [a-z0-9_]+, e.g. window_px)";
        if (d.type < BINOCLE_PARAM_BOOL || d.type > BINOCLE_PARAM_DOUBLE_LIST)
            return at + ": unknown type " + std::to_string(d.type) + " (expected a BINOCLE_PARAM_* value)";
        if (auto [it, fresh] = seen.emplace(d.name, i); !fresh)
            return at + ": the name is declared twice (also setting #" + std::to_string(it->second) + ")";
        if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) && (d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) && d.min > d.max)
            return at + ": min " + formatNumber(d.min) + " is above max " + formatNumber(d.max);
        if (d.type == BINOCLE_PARAM_ENUM && (!d.choices || !*d.choices)) return at + ": an enum without choices";
        if (d.flags & BINOCLE_PARAM_FLAG_REQUIRED) continue;
        if (!d.default_value) return at + ": no default, and not flagged BINOCLE_PARAM_FLAG_REQUIRED";
        if (std::string why = defaultProblem(d, d.default_value); !why.empty())
            return at + ": default '" + d.default_value + "' " + why;
    }
    return "";
}

} // namespace binocle
