// SPDX-License-Identifier: MIT
// A plugin's settings, and the plugin itself, as JSON: what the viewer's controls and the
// Python module's plugins() show of them.
#pragma once

#include <binocle/abi.h>

#include <nlohmann/json.hpp>

namespace binocle {

struct PluginRecord;

// "int", "double", "bool", "enum", "string", "path", "yaml", "int_list", "double_list"
// ("unknown" otherwise).
const char *settingTypeName(int32_t type);

// {"name", "type", "min", "max", "multiple_of", "odd", "limit" (a resource limit),
//  "required", "choices" (a list), "unit", "help", "default" (text, or null)}; the
// optional keys only when the table says so.
nlohmann::ordered_json settingJson(const binocle_param_desc &d);

// {"name", "kind", "version", "abi_version", "api_version", "description", "path",
//  "settings" (settingJson of each entry of its table, in the table's order)}.
nlohmann::ordered_json pluginJson(const PluginRecord &p);

} // namespace binocle
