// SPDX-License-Identifier: MIT
// Controls from the plugins' settings tables.
#include "viewer/settings_schema.hpp"

#include "host/setting_json.hpp"
#include "viewer/page_settings.hpp"

#include <sstream>

namespace binocle::viewer {

namespace {

using OJson = nlohmann::ordered_json;

OJson block(const PluginBlock &b, const std::string &key) {
    OJson out = {{"key", key}, {"where", b.where}, {"plugin", b.plugin}, {"kind", b.record ? kindName(b.record->kind) : ""}};
    OJson params = OJson::array();
    if (b.record) {
        for (const binocle_param_desc &d : b.record->params()) {
            OJson p = settingJson(d);
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
