// SPDX-License-Identifier: MIT
// One setting of a plugin's table as JSON: what the viewer's controls and the Python
// module's plugins() show of it.
#pragma once

#include <binocle/abi.h>

#include <nlohmann/json.hpp>

namespace binocle {

// "int", "double", "bool", "enum", "string", "path", "yaml", "int_list", "double_list"
// ("unknown" otherwise).
const char *settingTypeName(int32_t type);

// {"name", "type", "min", "max", "multiple_of", "odd", "limit" (a resource limit),
//  "required", "choices" (a list), "unit", "help", "default" (text, or null)}; the
// optional keys only when the table says so.
nlohmann::ordered_json settingJson(const binocle_param_desc &d);

} // namespace binocle
