// SPDX-License-Identifier: MIT
// What a page may change, and where its paths may point.
#include "viewer/page_settings.hpp"

#include "host/plugin_kinds.hpp"

#include <binocle/text.hpp>

#include <algorithm>

namespace fs = std::filesystem;

namespace binocle::viewer {

namespace {

// `p` with symbolic links resolved as far as it exists; empty when that fails.
fs::path resolved(const fs::path &p) {
    std::error_code ec;
    fs::path out = fs::weakly_canonical(p, ec);
    return ec ? fs::path() : out;
}

bool inside(const fs::path &p, const fs::path &folder) {
    auto f = folder.begin(), q = p.begin();
    for (; f != folder.end(); ++f, ++q)
        if (q == p.end() || *q != *f) return false;
    return true;
}

} // namespace

std::vector<std::pair<const PluginBlock *, std::string>> pluginBlocks(const RigConfig &rig) {
    // Every kind's blocks, in kind order, as its descriptor holds them in a rig.
    std::vector<std::pair<const PluginBlock *, std::string>> out;
    for (const PluginKind *k : pluginKinds()) {
        const auto &blocks = rig.blocks(k->kind);
        for (size_t i = 0; i < blocks.size(); ++i)
            out.emplace_back(&blocks[i], k->inRig == PluginKind::InRig::List ? std::string(k->rigKey) + "." + std::to_string(i)
                                                                             : std::string(k->rigKey));
    }
    return out;
}

PageSettings::PageSettings(const RigConfig &started) {
    auto addFolder = [&](const fs::path &folder) {
        const fs::path f = resolved(folder);
        if (!f.empty() && std::find(folders_.begin(), folders_.end(), f) == folders_.end()) folders_.push_back(f);
    };
    if (!started.base_dir.empty()) addFolder(started.base_dir);
    for (const auto &[block, prefix] : pluginBlocks(started)) {
        if (!block->record) continue;
        for (const binocle_param_desc &d : block->record->params()) {
            const std::string key = prefix + "." + d.name;
            settings_[key] = {d.type, (d.flags & BINOCLE_PARAM_FLAG_LIMIT) != 0};
            if (d.type != BINOCLE_PARAM_PATH) continue;
            const binocle_param *v = block->params.find(d.name);
            const std::string path = v && v->s ? v->s : "";
            startedPaths_[key] = path;
            // A glob pattern's folder (replay's left_*.png), or a file's.
            if (!path.empty()) addFolder(fs::path(path).parent_path());
        }
    }
}

std::string PageSettings::refuseKey(const std::string &key) const {
    const auto it = settings_.find(key);
    if (it == settings_.end())
        return "view: " + sdk::printable(key, 60) +
               " is not a setting of the rig's plugins; the page changes plugin settings only (runtime, outputs and "
               "which plugin runs are set in the rig file or with --set)";
    if (it->second.limit)
        return "view: " + key + " is a resource limit: it is set in the rig file or with --set, not from the page";
    return "";
}

std::string PageSettings::refusePaths(const RigConfig &candidate) const {
    for (const auto &[block, prefix] : pluginBlocks(candidate)) {
        if (!block->record) continue;
        for (const binocle_param_desc &d : block->record->params()) {
            if (d.type != BINOCLE_PARAM_PATH) continue;
            const std::string key = prefix + "." + d.name;
            const binocle_param *v = block->params.find(d.name);
            const std::string path = v && v->s ? v->s : "";
            const auto started = startedPaths_.find(key);
            if (path.empty() || (started != startedPaths_.end() && started->second == path)) continue;
            const fs::path p = resolved(path);
            const bool ok = !p.empty() && std::any_of(folders_.begin(), folders_.end(), [&](const fs::path &f) { return inside(p, f); });
            if (ok) continue;
            std::string where;
            for (const fs::path &f : folders_) where += (where.empty() ? "" : ", ") + f.string();
            return "view: " + key + " = " + sdk::printable(path, 120) +
                   ": a path from the page must lie inside the rig's folders (" + where +
                   "); other files are named in the rig file or with --set";
        }
    }
    return "";
}

} // namespace binocle::viewer
