// SPDX-License-Identifier: MIT
// Checks a plugin's settings against its own binocle_param_desc table with the SDK's one
// settings checker (binocle/settings.hpp), so that a plugin refuses bad values with the
// host's rules and words even when its host did not validate them.
//
// Header-only; plugins/common has no CMakeLists.txt on purpose (every folder with one
// is built as a plugin).
#pragma once

#include <binocle/settings.hpp>

#include <string>
#include <vector>

namespace binocle::plugins {

// Throws Error(BINOCLE_ERR_INVALID_ARGUMENT, "<plugin>: <key> = <value>: expected <what>").
// Plugins that read their settings through sdk::CheckedParams need not call this.
inline void checkParameters(const sdk::Params &params, const std::vector<binocle_param_desc> &table,
                            const std::string &plugin) {
    (void)sdk::CheckedParams(params, table, plugin);
}

} // namespace binocle::plugins
