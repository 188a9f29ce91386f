// SPDX-License-Identifier: MIT
// What a page may change: the declared settings of the rig's plugin blocks, less the
// resource limits; and where a path from a page may point: inside the rig's folders.
#pragma once

#include "config/rig_config.hpp"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace binocle::viewer {

// All settings a page has set, together, in bytes of key and value: each is copied into
// the state every page receives.
inline constexpr size_t kMaxPageSettingsBytes = 32 * 1024;

class PageSettings {
public:
    // From the rig as the command line started it (its file and --set): the folders are
    // the rig file's own and those of every path it names (configs/scenes for a rig in
    // configs/rigs naming ../scenes/x.yaml).
    explicit PageSettings(const RigConfig &started);

    // "" when a page may set `key`; otherwise why not, for the page. Refused: keys that
    // are not a declared setting of one of the rig's plugin blocks (runtime.*, outputs.*,
    // a block's plugin) and settings their plugin marks BINOCLE_PARAM_FLAG_LIMIT.
    std::string refuseKey(const std::string &key) const;

    // "" when every path setting of `candidate` is the one the rig started with, empty,
    // or lies (symbolic links resolved) inside one of folders(); otherwise which key and
    // why, naming the path (never anything the file holds).
    std::string refusePaths(const RigConfig &candidate) const;

    const std::vector<std::filesystem::path> &folders() const { return folders_; }

private:
    struct Setting {
        int32_t type;
        bool limit;
    };
    std::map<std::string, Setting> settings_;          // "matcher.num_disparities"
    std::map<std::string, std::string> startedPaths_; // key -> the path the rig started with
    std::vector<std::filesystem::path> folders_;       // canonical
};

// The rig's plugin blocks with their --set prefixes: source, matcher, transforms.N,
// evaluators.N.
std::vector<std::pair<const PluginBlock *, std::string>> pluginBlocks(const RigConfig &rig);

} // namespace binocle::viewer
