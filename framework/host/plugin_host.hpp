// SPDX-License-Identifier: MIT
// The plugin host: finds plugin files (binocle_<name>.so) on a safe search path, loads
// them with Boost.DLL (RTLD_NOW), checks their ABI and settings tables before calling
// anything else, and keeps a record of each file it accepted (PluginRecord) or refused.
// Including this header gives the whole public face of the module: the settings
// (plugin_settings.hpp), how an instance runs (plugin_instance.hpp: IsolationOptions),
// the frames a source lends (lent_frame.hpp) and the four kinds' wrappers
// (kind_<name>.hpp), each of which may run its plugin in a helper process
// (host/isolation.hpp).
#pragma once

#include "core/error.hpp"
#include "host/kind_evaluator.hpp"
#include "host/kind_matcher.hpp"
#include "host/kind_source.hpp"
#include "host/kind_transform.hpp"
#include "host/lent_frame.hpp"
#include "host/plugin_instance.hpp"
#include "host/plugin_record.hpp"
#include "host/plugin_settings.hpp"

#include <binocle/abi.h>

#include <deque>
#include <string>
#include <vector>

namespace binocle {

// The least table size the host accepts for a kind at an API version: the end of the
// last entry that version defines. Frozen per version; 0 for an unknown kind or version.
size_t leastTableSize(int32_t kind, uint32_t api_version);

// A file that looked like a plugin and was refused, with why.
struct Refusal {
    std::string path;
    std::string reason;
};

enum class ScanMode {
    InProcess, // open every file in this process (a crashing constructor takes it down)
    Isolated   // examine each file in a short-lived child first; open only those that pass
};

class PluginHost {
public:
    // $BINOCLE_PLUGIN_PATH (':'-separated), then <prefix>/lib/binocle/plugins, the prefix
    // of host/install_prefix.hpp (the running executable's, or the one a program named,
    // e.g. the Python module); the build tree mirrors that layout. No path is compiled in.
    static std::vector<std::string> defaultSearchPath();

    explicit PluginHost(std::vector<std::string> searchPath = defaultSearchPath());
    ~PluginHost();

    // Looks at every binocle_*.so in the search path (first folder wins for a file name).
    // Isolated: a file whose code crashes or hangs at load (child_timeout_ms) is refused
    // with the signal or the timeout, and the scan goes on.
    void scan(ScanMode mode = ScanMode::InProcess, int32_t child_timeout_ms = 2000) const;
    // Loads one file; throws binocle::Error naming the file and the reason.
    const PluginRecord &load(const std::string &path);

    // Records stay where they are while more plugins are opened (a deque).
    const std::deque<PluginRecord> &plugins() const { return plugins_; }
    const std::vector<Refusal> &refused() const { return refused_; }
    const std::vector<std::string> &searchPath() const { return searchPath_; }
    // Among the files opened so far; nullptr if absent (or of another kind when kind != 0).
    const PluginRecord *find(const std::string &name, int32_t kind = 0) const;
    // Like find, but opens binocle_<name>.so from the first folder of the search path that
    // holds it when it is not open yet, and no other file: a rig opens only what it names.
    // A refusal lands in refused(). The host is a cache of opened files, hence const.
    const PluginRecord *lookup(const std::string &name, int32_t kind = 0) const;
    // The file binocle_<name>.so in the first safe folder of the search path that holds
    // one, without opening it; "" when there is none.
    std::string locate(const std::string &name) const;
    // Throws Error "no <kind> plugin named 'x' (found: a, b, c)"; opens the file like lookup.
    const PluginRecord &require(const std::string &name, int32_t kind) const;
    // Like lookup for a plugin that runs isolated: binocle_<name>.so is read by a helper
    // process (describeInHelper, at most timeout_ms), never opened here, so none of its
    // code runs in this process. A refusal (the signal of a crash, a timeout) lands in
    // refused(). The record is described (no library).
    const PluginRecord *describe(const std::string &name, int32_t kind = 0, int32_t timeout_ms = 15000) const;
    // The records describe() made.
    const std::deque<PluginRecord> &described() const { return described_; }

private:
    std::vector<std::string> searchPath_;
    mutable std::deque<PluginRecord> plugins_;
    mutable std::deque<PluginRecord> described_;
    mutable std::vector<Refusal> refused_;
    const PluginRecord &inspect(const std::string &path) const; // throws with reason
    // Folders of the search path that are safe to load from; unsafe ones are refused once.
    std::vector<std::string> safeFolders() const;
    bool known(const std::string &canonical) const;
};

} // namespace binocle
