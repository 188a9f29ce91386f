// SPDX-License-Identifier: MIT
// Rig descriptions in YAML: one file composes a source, a calibration, a matcher, cloud
// transforms, evaluators and outputs. Every plugin block is validated against the
// plugin's own settings table; errors name file, line, column, key, value and what was
// expected.
#pragma once

#include "core/error.hpp"
#include "host/plugin_host.hpp"

#include <map>
#include <optional>
#include <string>
#include <vector>
#include <yaml-cpp/yaml.h>

namespace binocle {

// Where a node came from, for error messages: "rig.yaml:12:5" or "--set matcher.x=1".
struct Location {
    std::string file;
    int line = 0, column = 0; // 1-based; 0 when the value came from the command line
    std::string override;      // the --set text, when it came from there
    std::string str() const;
};

// One plugin block: `plugin: <name>` plus that plugin's settings.
struct PluginBlock {
    std::string where;  // "matcher", "transforms[0]"
    std::string plugin; // plugin name
    const PluginRecord *record = nullptr;
    ParamValues params;
    IsolationOptions isolation; // how its instances run (`isolation: process` ...)
    Location location;
};

struct OutputOptions {
    bool disparity_png = true;   // 16-bit KITTI PNG
    bool disparity_color = true; // colourised PNG
    bool disparity_pfm = false;
    bool cloud_ply = true;
    bool rectified_png = false;
    double max_range_mm = 50000; // points farther are dropped from the cloud
};

// The rig's `runtime:` block: how the stage pipeline runs (README "Runtime").
struct RuntimeOptions {
    enum class Policy { Lossless, Latest };
    // Unset: the source decides (`latest` for a live source, `lossless` otherwise).
    std::optional<Policy> policy;
    int queue_depth = 4;           // frames waiting between two stages
    int matcher_instances = 1;     // parallel matcher instances, each on its own thread
    enum class OnSourceError { Stop, Retry };
    OnSourceError on_source_error = OnSourceError::Stop;
    double retry_for_s = 30;       // with retry: how long the source may stay in error
};

struct RigConfig {
    std::string file;     // absolute path of the YAML
    std::string base_dir; // its folder: relative paths resolve against it
    std::string name;
    // Every plugin block, by kind (BINOCLE_KIND_*), in the rig's order. Each kind's
    // descriptor (host/plugin_kinds.hpp) says where a rig file holds its blocks (its rig
    // key; one block, at most one, or a list): a new kind adds nothing here.
    std::map<int32_t, std::vector<PluginBlock>> plugins;
    std::optional<std::string> calibration_file; // overrides the source's calibration
    OutputOptions outputs;
    RuntimeOptions runtime;
    std::string resolved_yaml; // the rig after --set overrides

    // A kind's blocks; empty when the rig has none.
    const std::vector<PluginBlock> &blocks(int32_t kind) const;
    // The kinds every rig has (a rig is refused without a source and a matcher).
    const PluginBlock &source() const { return blocks(BINOCLE_KIND_STEREO_SOURCE).at(0); }
    const PluginBlock &matcher() const { return blocks(BINOCLE_KIND_MATCHER).at(0); }
    const std::vector<PluginBlock> &transforms() const { return blocks(BINOCLE_KIND_CLOUD_TRANSFORM); }
    const std::vector<PluginBlock> &evaluators() const { return blocks(BINOCLE_KIND_EVALUATOR); }
};

// A mistake in a value that came from the command line (--set): the command reports it
// as wrong usage (exit status 2), with the same words as the same value in the file.
class OverrideError : public Error {
public:
    using Error::Error;
};

// "key=value" with a dotted key path ("matcher.num_disparities=128",
// "transforms.0.inclination_deg=10"); the value is parsed as YAML.
struct Override {
    std::string path;
    std::string value;
    std::string text;
    static Override parse(const std::string &text); // throws OverrideError on a malformed text
};

// Loads, applies overrides, validates against the plugins `host` found.
RigConfig loadRig(const std::string &file, const std::vector<Override> &overrides, const PluginHost &host);
// Same from the rig's text; `file` names it in messages and anchors relative paths.
RigConfig loadRigText(const std::string &text, const std::string &file, const std::vector<Override> &overrides,
                      const PluginHost &host);
// Same from a YAML tree already loaded (experiments build rigs this way).
RigConfig rigFromNode(const YAML::Node &root, const std::string &file, const PluginHost &host);

// Applies one override to a tree; creates missing maps; throws OverrideError on a path
// through a scalar.
void applyOverride(YAML::Node &root, const Override &o);

// Validates a plugin block against the plugin's table and returns the values it gets.
// `block` is a map with `plugin:` (ignored here) and settings.
ParamValues resolveParams(const PluginRecord &record, const YAML::Node &block, const std::string &where,
                          const std::string &file, const std::string &base_dir);
// All defaults of a plugin, plus the given YAML text (a map) on top: handy for tests.
ParamValues paramsFromYaml(const PluginRecord &record, const std::string &yaml = "{}");

} // namespace binocle
