// SPDX-License-Identifier: MIT
// A plugin's settings, header-only: how it declares them (Param, its table of
// binocle_param_desc), the one settings checker (how the text of a setting reads and
// whether a value fits its description: type, min, max, odd, multiple of, choices) and
// CheckedParams, the values `create` received checked against the table. The host
// checks every rig setting, `runtime:` key, isolation key and --set with this checker,
// and the SDK hands a plugin's constructor its CheckedParams (plugin.hpp), so the same
// value gets the same answer in a rig file, on the command line and inside a plugin, in
// the same words.
//
// Numbers follow binocle/numbers.hpp: decimal only, "0100" and "0x10" are errors.
#pragma once

#include <binocle/abi.h>
#include <binocle/error.hpp>
#include <binocle/numbers.hpp>
#include <binocle/text.hpp>

#include <cmath>
#include <cstdint>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace binocle::sdk {

// Builder for binocle_param_desc. All strings must be literals (static storage).
class Param {
public:
    static Param boolean(const char *name, bool def) { return Param(name, BINOCLE_PARAM_BOOL, def ? "true" : "false"); }
    static Param integer(const char *name, const char *def) { return Param(name, BINOCLE_PARAM_INT, def); }
    static Param real(const char *name, const char *def) { return Param(name, BINOCLE_PARAM_DOUBLE, def); }
    static Param string(const char *name, const char *def) { return Param(name, BINOCLE_PARAM_STRING, def); }
    static Param path(const char *name, const char *def) { return Param(name, BINOCLE_PARAM_PATH, def); }
    static Param yaml(const char *name, const char *def) { return Param(name, BINOCLE_PARAM_YAML, def); }
    static Param intList(const char *name, const char *def) { return Param(name, BINOCLE_PARAM_INT_LIST, def); }
    static Param realList(const char *name, const char *def) { return Param(name, BINOCLE_PARAM_DOUBLE_LIST, def); }
    // choices: "a|b|c"
    static Param choice(const char *name, const char *def, const char *choices) {
        Param p(name, BINOCLE_PARAM_ENUM, def);
        p.d_.choices = choices;
        return p;
    }
    // A setting without default that the YAML must give.
    Param &required() { d_.flags |= BINOCLE_PARAM_FLAG_REQUIRED; d_.default_value = nullptr; return *this; }
    Param &min(double v) { d_.flags |= BINOCLE_PARAM_FLAG_HAS_MIN; d_.min = v; return *this; }
    Param &max(double v) { d_.flags |= BINOCLE_PARAM_FLAG_HAS_MAX; d_.max = v; return *this; }
    Param &odd() { d_.flags |= BINOCLE_PARAM_FLAG_ODD; return *this; }
    // A resource limit (memory, time): the rig or --set sets it, a live page cannot.
    Param &limit() { d_.flags |= BINOCLE_PARAM_FLAG_LIMIT; return *this; }
    Param &multipleOf(int64_t m) { d_.multiple_of = m; return *this; }
    Param &unit(const char *u) { d_.unit = u; return *this; }
    Param &help(const char *h) { d_.help = h; return *this; }
    operator binocle_param_desc() const { return d_; } // NOLINT: meant to convert

private:
    Param(const char *name, int32_t type, const char *def) {
        d_.name = name;
        d_.type = type;
        d_.default_value = def;
        d_.unit = "";
        d_.help = "";
    }
    binocle_param_desc d_{};
};

// The values `create` received, by name, as the host passed them. A plugin reads
// CheckedParams instead (below): the SDK builds it from this before the constructor.
class Params {
public:
    Params(const binocle_param *params, int32_t count) {
        for (int32_t i = 0; i < count; ++i) byName_[params[i].name] = params[i];
    }
    bool has(const std::string &name) const { return byName_.count(name) != 0; }
    // True when the user set the value (YAML or --set), false for defaults.
    bool isExplicit(const std::string &name) const { return get(name).explicit_ != 0; }
    int64_t integer(const std::string &name) const { return get(name).i; }
    bool boolean(const std::string &name) const { return get(name).i != 0; }
    double real(const std::string &name) const {
        const binocle_param &p = get(name);
        return p.type == BINOCLE_PARAM_INT ? static_cast<double>(p.i) : p.d;
    }
    // STRING, ENUM, PATH, YAML and lists (as YAML text).
    std::string string(const std::string &name) const {
        const char *s = get(name).s;
        return s ? s : "";
    }

private:
    const binocle_param &get(const std::string &name) const {
        auto it = byName_.find(name);
        if (it == byName_.end())
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "no setting named '" + name + "' (plugin bug: not declared)");
        return it->second;
    }
    std::map<std::string, binocle_param> byName_;
};

// 1500, 0.5, -90, 3600000: as short as the number allows, whole numbers in full.
inline std::string settingNumberText(double v) {
    if (std::isfinite(v) && v == std::trunc(v) && std::fabs(v) < 1e15) return std::to_string(static_cast<long long>(v));
    std::ostringstream s;
    s.precision(15);
    s << v;
    return s.str();
}

// An enum's choices: "a|b|c" -> {a, b, c}.
inline std::vector<std::string> settingChoices(const binocle_param_desc &d) {
    std::vector<std::string> out;
    const std::string all = d.choices ? d.choices : "";
    size_t start = 0;
    while (start <= all.size()) {
        size_t end = all.find('|', start);
        if (end == std::string::npos) end = all.size();
        out.push_back(all.substr(start, end - start));
        start = end + 1;
    }
    return out;
}

// An INT setting without a bound of its own holds 32 bits: plugins keep it in an `int`.
constexpr double kSettingIntLeast = -2147483648.0, kSettingIntMost = 2147483647.0;

// Everything setting `d` accepts, in words: "an odd integer >= 5 <= 255",
// "a decimal number >= 0", "bm or sgbm", "one of grey, yuyv, mjpeg", "true or false".
inline std::string settingExpects(const binocle_param_desc &d) {
    auto range = [&](std::string what) {
        if (d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) what += " >= " + settingNumberText(d.min);
        if (d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) what += " <= " + settingNumberText(d.max);
        return what;
    };
    switch (d.type) {
    case BINOCLE_PARAM_BOOL: return "true or false";
    case BINOCLE_PARAM_INT: {
        std::string what = "an integer";
        if (d.multiple_of > 0) what = "an integer multiple of " + std::to_string(d.multiple_of);
        if (d.flags & BINOCLE_PARAM_FLAG_ODD) what = "an odd integer";
        return range(what);
    }
    case BINOCLE_PARAM_DOUBLE: return range("a decimal number");
    case BINOCLE_PARAM_ENUM: {
        const std::vector<std::string> choices = settingChoices(d);
        if (choices.size() == 2) return choices[0] + " or " + choices[1];
        std::string all;
        for (const auto &c : choices) all += (all.empty() ? "" : ", ") + c;
        return "one of " + all;
    }
    case BINOCLE_PARAM_INT_LIST: return "a list of integers, e.g. [1, 2]";
    case BINOCLE_PARAM_DOUBLE_LIST: return "a list of numbers, e.g. [0.1, 0.2]";
    case BINOCLE_PARAM_PATH: return "a path";
    case BINOCLE_PARAM_YAML: return "YAML";
    default: return "a text";
    }
}

// A value of a setting, by its type.
struct SettingValue {
    int32_t type = 0;
    bool boolean = false;
    int64_t integer = 0;
    double real = 0;  // DOUBLE; INT as a double too
    std::string text; // ENUM, STRING, PATH, YAML and lists (as YAML text)
};

// Why a text or value does not fit its setting; false (empty) when it fits.
struct SettingProblem {
    // The rule broken, to follow the value: "is not odd", "is below its min 3",
    // "is not an integer: expected a decimal integer without leading zeros (...)".
    std::string rule;
    // What the setting accepts, and the reader's reason when the text is not read as a
    // number at all: "an integer multiple of 16 >= 16, without leading zeros (0100 would
    // read as octal 64 elsewhere: write 100)".
    std::string expected;
    explicit operator bool() const { return !rule.empty(); }
};

// Checks a number against the bounds, oddness and multiple of `d` (INT or DOUBLE);
// `exact`, when given, is the integer itself (a double cannot tell 2^53 + 1 from 2^53).
inline SettingProblem checkSettingNumber(const binocle_param_desc &d, double v, const int64_t *exact = nullptr) {
    const std::string expects = settingExpects(d);
    if (!std::isfinite(v)) return {"is not finite", expects};
    if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) && v < d.min) return {"is below its min " + settingNumberText(d.min), expects};
    if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) && v > d.max) return {"is above its max " + settingNumberText(d.max), expects};
    if (d.type != BINOCLE_PARAM_INT) return {};
    if ((!(d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) && v < kSettingIntLeast) ||
        (!(d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) && v > kSettingIntMost))
        return {"is not within 32 bits", expects + " (within 32 bits)"};
    if (v != std::trunc(v)) return {"is not an integer", expects};
    if (!exact && !(v >= -9223372036854775808.0 && v < 9223372036854775808.0)) return {"is not within 64 bits", expects};
    const int64_t i = exact ? *exact : static_cast<int64_t>(v);
    if ((d.flags & BINOCLE_PARAM_FLAG_ODD) && i % 2 == 0) return {"is not odd", expects};
    if (d.multiple_of > 0 && i % d.multiple_of != 0) return {"is not a multiple of " + std::to_string(d.multiple_of), expects};
    return {};
}

namespace detail {

// "is not an integer" plus the reader's reason when it says more than that.
inline SettingProblem unreadable(const binocle_param_desc &d, const char *rule, const std::string &why) {
    const std::string detail = numberWhyDetail(why);
    return {std::string(rule) + (detail.empty() ? "" : ": " + why), settingExpects(d) + detail};
}

// "[1, 2.5]" -> {"1", "2.5"}; false when the text is not a flow list of scalars.
inline bool splitFlowList(std::string_view text, std::vector<std::string_view> &items) {
    auto trim = [](std::string_view s) {
        while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
        while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
        return s;
    };
    text = trim(text);
    if (text.size() < 2 || text.front() != '[' || text.back() != ']') return false;
    text = trim(text.substr(1, text.size() - 2));
    items.clear();
    if (text.empty()) return true;
    size_t start = 0;
    while (start <= text.size()) {
        size_t end = text.find(',', start);
        if (end == std::string_view::npos) end = text.size();
        items.push_back(trim(text.substr(start, end - start)));
        start = end + 1;
    }
    return true;
}

} // namespace detail

// Reads `text` (a YAML scalar, a --set value, a plugin's default) as a value of setting
// `d` and checks it. Lists are read from their flow text ("[1, 2]"), each element a
// number by the same reader; strings, paths and YAML take any text.
inline SettingProblem readSetting(const binocle_param_desc &d, std::string_view text, SettingValue &out) {
    out = SettingValue{};
    out.type = d.type;
    std::string why;
    switch (d.type) {
    case BINOCLE_PARAM_BOOL:
        if (!parseBoolean(text, out.boolean)) return {"is not a boolean (true or false)", settingExpects(d)};
        out.integer = out.boolean ? 1 : 0;
        return {};
    case BINOCLE_PARAM_INT:
        if (!parseDecimalInteger(text, out.integer, &why))
            return detail::unreadable(d, "is not an integer", why);
        out.real = static_cast<double>(out.integer);
        return checkSettingNumber(d, out.real, &out.integer);
    case BINOCLE_PARAM_DOUBLE:
        if (!parseDecimalReal(text, out.real, &why))
            return detail::unreadable(d, "is not a number", why);
        return checkSettingNumber(d, out.real);
    case BINOCLE_PARAM_ENUM:
        out.text = std::string(text);
        for (const auto &c : settingChoices(d))
            if (c == text && !c.empty()) return {};
        return {std::string("is not one of its choices '") + (d.choices ? d.choices : "") + "'", settingExpects(d)};
    case BINOCLE_PARAM_INT_LIST:
    case BINOCLE_PARAM_DOUBLE_LIST: {
        out.text = std::string(text);
        std::vector<std::string_view> items;
        if (!detail::splitFlowList(text, items)) return {"is not a list", settingExpects(d)};
        for (const auto item : items) {
            int64_t i = 0;
            double x = 0;
            const bool ok = d.type == BINOCLE_PARAM_INT_LIST ? parseDecimalInteger(item, i, &why)
                                                             : parseDecimalReal(item, x, &why);
            if (!ok)
                return {"holds '" + printable(item, 40) + "': " + why,
                        settingExpects(d) + " ('" + printable(item, 40) + "': " + why + ")"};
        }
        return {};
    }
    default: out.text = std::string(text); return {};
    }
}

// Checks a value as `create` receives it (binocle_param) against its setting: what a
// plugin sees is what the host would have accepted.
inline SettingProblem checkSetting(const binocle_param_desc &d, const binocle_param &p) {
    switch (d.type) {
    case BINOCLE_PARAM_INT: {
        if (p.type == BINOCLE_PARAM_DOUBLE) return checkSettingNumber(d, p.d); // not whole: refused there
        SettingValue v;
        return readSetting(d, std::to_string(p.i), v);
    }
    case BINOCLE_PARAM_DOUBLE: return checkSettingNumber(d, p.type == BINOCLE_PARAM_INT ? static_cast<double>(p.i) : p.d);
    case BINOCLE_PARAM_ENUM: {
        SettingValue v;
        return readSetting(d, p.s ? p.s : "", v);
    }
    default: return {};
    }
}

// The words every plugin-side refusal uses: "<plugin>: <key> = <value>: expected <what>".
inline std::string settingMessage(const std::string &plugin, const std::string &key, const std::string &value,
                                  const std::string &expected) {
    return plugin + ": " + key + " = " + value + ": expected " + expected;
}

// The settings `create` received, checked against the plugin's own table: a setting the
// host did not pass reads as its default, every value fits its description, and asking
// for a name the table lacks is a plugin bug. Throws Error(BINOCLE_ERR_INVALID_ARGUMENT,
// settingMessage(...)). The SDK builds it from the plugin's parameters() before the
// constructor runs (a refusal fails `create` in these words) and hands it to a
// constructor that takes one, so a plugin reads its settings without restating its
// table (defaults, bounds, choices) in code:
//
//   MyMatcher(const sdk::CheckedParams &p, sdk::Host &)
//       : window_(static_cast<int>(p.integer("window_px"))) {}
class CheckedParams {
public:
    CheckedParams(const Params &params, const std::vector<binocle_param_desc> &table, std::string plugin)
        : plugin_(std::move(plugin)) {
        for (const binocle_param_desc &d : table) {
            Entry e;
            e.desc = d;
            const std::string key = d.name;
            if (params.has(key)) {
                e.isExplicit = params.isExplicit(key);
                e.value.type = d.type;
                binocle_param p{};
                p.name = d.name;
                p.type = d.type;
                switch (d.type) {
                case BINOCLE_PARAM_BOOL: e.value.boolean = params.boolean(key); break;
                case BINOCLE_PARAM_INT:
                    e.value.integer = params.integer(key);
                    e.value.real = static_cast<double>(e.value.integer);
                    p.i = e.value.integer;
                    break;
                case BINOCLE_PARAM_DOUBLE: e.value.real = p.d = params.real(key); break;
                default: e.value.text = params.string(key); break;
                }
                const std::string text = d.type == BINOCLE_PARAM_ENUM ? e.value.text : "";
                p.s = text.c_str();
                if (SettingProblem why = checkSetting(d, p)) refuse(key, valueText(e.value), why.expected);
            } else if (d.default_value) {
                if (SettingProblem why = readSetting(d, d.default_value, e.value))
                    refuse(key, std::string("'") + d.default_value + "' (its default)", why.expected);
            } else {
                refuse(key, "(nothing)", settingExpects(d) + " (the setting has no default)");
            }
            entries_[key] = std::move(e);
        }
    }

    int64_t integer(const std::string &name) const { return get(name).value.integer; }
    double real(const std::string &name) const { return get(name).value.real; }
    bool boolean(const std::string &name) const { return get(name).value.boolean; }
    // ENUM, STRING, PATH, YAML and lists (as YAML text).
    const std::string &string(const std::string &name) const { return get(name).value.text; }
    // True when the user set the value (YAML or --set), false for defaults.
    bool isExplicit(const std::string &name) const { return get(name).isExplicit; }

    // A rule across settings ("an even width with layout side_by_side") in the same words.
    [[noreturn]] void refuse(const std::string &key, const std::string &value, const std::string &expected) const {
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT, settingMessage(plugin_, key, value, expected));
    }

private:
    struct Entry {
        binocle_param_desc desc{};
        SettingValue value;
        bool isExplicit = false;
    };
    static std::string valueText(const SettingValue &v) {
        switch (v.type) {
        case BINOCLE_PARAM_INT: return std::to_string(v.integer);
        case BINOCLE_PARAM_DOUBLE: return settingNumberText(v.real);
        default: return "'" + printable(v.text) + "'";
        }
    }
    const Entry &get(const std::string &name) const {
        auto it = entries_.find(name);
        if (it == entries_.end())
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, plugin_ + ": no setting named '" + name + "' (plugin bug: not declared)");
        return it->second;
    }
    std::string plugin_;
    std::map<std::string, Entry> entries_;
};

} // namespace binocle::sdk

// This header brought plugin.hpp with it before Param and Params moved here: kept, so
// that a plugin that includes only settings.hpp still compiles. plugin.hpp includes
// this header first, so either order defines everything.
#include <binocle/plugin.hpp>
