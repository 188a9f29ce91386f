// SPDX-License-Identifier: MIT
// A plugin's settings: the values an instance is made with (ParamValues), and the checks
// of its settings table (names, types, defaults), apart from loading: the settings
// checker's home in the host.
#include "host/plugin_settings.hpp"

#include "host/plugin_host.hpp"
#include "host/plugin_name.hpp"
#include "host/setting_json.hpp"

#include <binocle/settings.hpp>

#include <map>
#include <sstream>
#include <string>

namespace binocle {

// ---- Settings values ----------------------------------------------------------------------

binocle_param &ParamValues::slot(const std::string &name) {
    for (auto &p : values_)
        if (name == p.name) return p;
    strings_.push_back(std::make_shared<std::string>(name));
    binocle_param p{};
    p.name = strings_.back()->c_str();
    values_.push_back(p);
    return values_.back();
}

void ParamValues::setBool(const std::string &name, bool v, bool isExplicit) {
    auto &p = slot(name);
    p.type = BINOCLE_PARAM_BOOL;
    p.i = v ? 1 : 0;
    p.explicit_ = isExplicit;
}

void ParamValues::setInt(const std::string &name, int64_t v, bool isExplicit) {
    auto &p = slot(name);
    p.type = BINOCLE_PARAM_INT;
    p.i = v;
    p.d = static_cast<double>(v);
    p.explicit_ = isExplicit;
}

void ParamValues::setDouble(const std::string &name, double v, bool isExplicit) {
    auto &p = slot(name);
    p.type = BINOCLE_PARAM_DOUBLE;
    p.d = v;
    p.explicit_ = isExplicit;
}

void ParamValues::setText(const std::string &name, int32_t type, const std::string &v, bool isExplicit) {
    auto &p = slot(name);
    strings_.push_back(std::make_shared<std::string>(v));
    p.type = type;
    p.s = strings_.back()->c_str();
    p.explicit_ = isExplicit;
}

const binocle_param *ParamValues::data() const { return values_.data(); }
int32_t ParamValues::size() const { return static_cast<int32_t>(values_.size()); }

const binocle_param *ParamValues::find(const std::string &name) const {
    for (const auto &p : values_)
        if (name == p.name) return &p;
    return nullptr;
}

// ---- Settings tables --------------------------------------------------------------------

namespace {

// Why `text` is not a valid value of setting `d`, or "" when it is: the SDK's settings
// checker, the one the rig validation (config/) uses, applied to the plugin's own default.
std::string defaultProblem(const binocle_param_desc &d, const std::string &text) {
    sdk::SettingValue v;
    return sdk::readSetting(d, text, v).rule;
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
            return at + ": min " + sdk::settingNumberText(d.min) + " is above max " + sdk::settingNumberText(d.max);
        if (d.type == BINOCLE_PARAM_ENUM && (!d.choices || !*d.choices)) return at + ": an enum without choices";
        if (d.flags & BINOCLE_PARAM_FLAG_REQUIRED) continue;
        if (!d.default_value) return at + ": no default, and not flagged BINOCLE_PARAM_FLAG_REQUIRED";
        if (std::string why = defaultProblem(d, d.default_value); !why.empty())
            return at + ": default '" + d.default_value + "' " + why;
    }
    return "";
}

// ---- A setting as JSON ------------------------------------------------------------------

const char *settingTypeName(int32_t type) {
    switch (type) {
    case BINOCLE_PARAM_BOOL: return "bool";
    case BINOCLE_PARAM_INT: return "int";
    case BINOCLE_PARAM_DOUBLE: return "double";
    case BINOCLE_PARAM_STRING: return "string";
    case BINOCLE_PARAM_ENUM: return "enum";
    case BINOCLE_PARAM_PATH: return "path";
    case BINOCLE_PARAM_YAML: return "yaml";
    case BINOCLE_PARAM_INT_LIST: return "int_list";
    case BINOCLE_PARAM_DOUBLE_LIST: return "double_list";
    default: return "unknown";
    }
}

nlohmann::ordered_json settingJson(const binocle_param_desc &d) {
    using OJson = nlohmann::ordered_json;
    OJson p = {{"name", d.name}, {"type", settingTypeName(d.type)}};
    if (d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) p["min"] = d.min;
    if (d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) p["max"] = d.max;
    if (d.multiple_of > 0) p["multiple_of"] = d.multiple_of;
    if (d.flags & BINOCLE_PARAM_FLAG_ODD) p["odd"] = true;
    if (d.flags & BINOCLE_PARAM_FLAG_LIMIT) p["limit"] = true;
    if (d.flags & BINOCLE_PARAM_FLAG_REQUIRED) p["required"] = true;
    if (d.choices) {
        OJson choices = OJson::array();
        std::stringstream ss(d.choices);
        for (std::string c; std::getline(ss, c, '|');) choices.push_back(c);
        p["choices"] = choices;
    }
    p["unit"] = d.unit ? d.unit : "";
    p["help"] = d.help ? d.help : "";
    p["default"] = d.default_value ? OJson(d.default_value) : OJson(nullptr);
    return p;
}

nlohmann::ordered_json pluginJson(const PluginRecord &p) {
    nlohmann::ordered_json settings = nlohmann::ordered_json::array();
    for (const binocle_param_desc &d : p.params()) settings.push_back(settingJson(d));
    return {{"name", p.name},
            {"kind", kindName(p.kind)},
            {"version", p.version},
            {"abi_version", p.abi_version},
            {"api_version", p.api_version},
            {"description", p.description},
            {"path", p.path},
            {"settings", std::move(settings)}};
}

} // namespace binocle
