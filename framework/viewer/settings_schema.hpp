// SPDX-License-Identifier: MIT
// The page's controls, generated from the plugins' own settings tables
// (binocle_param_desc): one group per plugin block of the rig, with current values.
#pragma once

#include "config/rig_config.hpp"

#include <nlohmann/json.hpp>

namespace binocle::viewer {

// [{"key": "matcher", "where": "matcher", "plugin": "sgbm", "kind": "matcher",
//   "params": [{"name", "type" ("int", "double", "bool", "enum", "string", "path", "yaml",
//   "int_list", "double_list"), "min", "max", "multiple_of", "odd", "limit" (a resource
//   limit: shown, not changed from the page), "choices", "unit",
//   "help", "default", "value" (YAML text), "explicit"}]}]
// `key` is the --set prefix of the block ("transforms.0").
nlohmann::ordered_json settingsSchema(const RigConfig &rig);

// The YAML text of one current value, as --set takes it.
std::string paramText(const binocle_param &p);

} // namespace binocle::viewer
