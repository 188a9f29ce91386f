// SPDX-License-Identifier: MIT
// JSON for result files (summary.json, results.json, reports): nlohmann/json, keys in
// insertion order, written so that a file is always valid JSON.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace binocle {

using Json = nlohmann::ordered_json;

// Indented text with a final newline. Non-finite numbers are written as null (JSON has no
// NaN) and invalid UTF-8 in strings is replaced by U+FFFD, so the file always parses.
inline std::string dumpJson(const Json &j, int indent = 2) {
    return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

} // namespace binocle
