// SPDX-License-Identifier: MIT
// Controls from the plugins' settings tables.
#include "viewer/settings_schema.hpp"

#include "viewer/page_settings.hpp"

#include <sstream>

namespace binocle::viewer {

namespace {

using OJson = nlohmann::ordered_json;

const char *typeName(int32_t type) {
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

OJson block(const PluginBlock &b, const std::string &key) {
    OJson out = {{"key", key}, {"where", b.where}, {"plugin", b.plugin}, {"kind", b.record ? kindName(b.record->kind) : ""}};
    OJson params = OJson::array();
    if (b.record) {
        for (const binocle_param_desc &d : b.record->params()) {
            OJson p = {{"name", d.name}, {"type", typeName(d.type)}};
            if (d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) p["min"] = d.min;
            if (d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) p["max"] = d.max;
            if (d.multiple_of > 0) p["multiple_of"] = d.multiple_of;
            if (d.flags & BINOCLE_PARAM_FLAG_ODD) p["odd"] = true;
            if (d.flags & BINOCLE_PARAM_FLAG_LIMIT) p["limit"] = true; // shown, not a control
            if (d.choices) {
                OJson choices = OJson::array();
                std::stringstream ss(d.choices);
                for (std::string c; std::getline(ss, c, '|');) choices.push_back(c);
                p["choices"] = choices;
            }
            p["unit"] = d.unit ? d.unit : "";
            p["help"] = d.help ? d.help : "";
            p["default"] = d.default_value ? OJson(d.default_value) : OJson(nullptr);
            if (const binocle_param *v = b.params.find(d.name)) {
                p["value"] = paramText(*v);
                p["explicit"] = v->explicit_ != 0;
            }
            params.push_back(p);
        }
    }
    out["params"] = params;
    return out;
}

} // namespace

std::string paramText(const binocle_param &p) {
    switch (p.type) {
    case BINOCLE_PARAM_BOOL: return p.i ? "true" : "false";
    case BINOCLE_PARAM_INT: return std::to_string(p.i);
    case BINOCLE_PARAM_DOUBLE: {
        std::ostringstream os;
        os.precision(10);
        os << p.d;
        return os.str();
    }
    default: return p.s ? p.s : "";
    }
}

OJson settingsSchema(const RigConfig &rig) {
    OJson blocks = OJson::array();
    for (const auto &[b, key] : pluginBlocks(rig)) blocks.push_back(block(*b, key));
    return blocks;
}

} // namespace binocle::viewer
