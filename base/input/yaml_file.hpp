// SPDX-License-Identifier: MIT
// YAML from untrusted files and command lines: one loader that refuses what yaml-cpp
// lets through silently (duplicate keys, ill-formed UTF-8, huge files) and says where.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

namespace binocle::input {

// Rigs and experiments are a few kilobytes; a larger file is a mistake (and emitting a
// 100 MB scalar back out costs yaml-cpp minutes).
constexpr uint64_t kMaxConfigFileBytes = uint64_t{1} << 20;

class YamlError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Parses `text`; `origin` names it in messages ("/x/rig.yaml", "--set a.b=1"). Throws
// YamlError "<origin>:<line>:<col>: ..." on ill-formed UTF-8, a syntax error, or a key
// given twice in one map ("key 'matcher' given twice: first at 3:1, again at 9:1").
YAML::Node parseYaml(const std::string &text, const std::string &origin);

// Reads and parses a file: refused when missing, not a regular file or larger than
// `maxBytes`.
YAML::Node loadYamlFile(const std::string &path, uint64_t maxBytes = kMaxConfigFileBytes);

// Throws YamlError for the first map of the tree that holds a key twice. Aliased
// nodes are visited once, so an alias bomb costs no more than its text.
void checkDuplicateKeys(const YAML::Node &root, const std::string &origin);

// The one check of a map's keys against the keys it may hold, for rigs, experiments,
// scenes and every other YAML Binocle reads. A key that is not valid is named with the
// nearest valid one and the whole list:
//   "unknown key 'matchr'; did you mean 'matcher'? (valid keys: name, source, matcher)"
struct UnknownKey {
    YAML::Node key;      // the offending key, for its position
    std::string name;    // as written ("(a non-scalar key)" when it is not a scalar)
    std::string message; // as above
};
// The first key of `map` not in `valid`; nullopt when there is none or `map` is no map.
// `owner`, when given, follows the key in the message ("unknown key 'x' for plugin 'bm'; ...").
std::optional<UnknownKey> findUnknownKey(const YAML::Node &map, const std::vector<std::string> &valid,
                                         const std::string &owner = "");

// Throws YamlError "<origin>:<line>:<col>: <what>: <message>" for the first unknown key,
// or "<origin>:<line>:<col>: <what>: expected a map" when `map` is not one.
void checkKeys(const YAML::Node &map, const std::vector<std::string> &valid, const std::string &what,
               const std::string &origin);

// "<origin>:<line>:<col>" of a node, or `origin` when the node has no position.
std::string located(const YAML::Node &node, const std::string &origin);

} // namespace binocle::input
