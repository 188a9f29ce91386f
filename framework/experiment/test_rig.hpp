// SPDX-License-Identifier: MIT
// The rig of one test: the variables of METHOD.md, where they go in a rig (bind), and the
// small YAML helpers the experiment's files share. Internal to framework/experiment.
#pragma once

#include "experiment/experiment.hpp"

#include <map>
#include <optional>
#include <string>
#include <vector>
#include <yaml-cpp/yaml.h>

namespace binocle::experiment {

// The variables a test may set, as written in the file and in results.csv.
extern const std::vector<std::string> kVariables;

// The member of `g` a variable names; nullptr for another name.
double *field(TestGeometry &g, const std::string &name);
double valueOf(const TestGeometry &g, const std::string &name);

std::string join(const std::vector<std::string> &v);
std::string num(double v);          // shortest decimal text ("1500", "0.5")
std::string yamlBlock(const YAML::Node &n);
std::string yamlText(const YAML::Node &n); // flow style, one line: a value for an override

// The rig paths each variable goes to, when the experiment does not say (`bind:`).
std::map<std::string, std::vector<std::string>> defaultBind(const YAML::Node &rig, const PluginHost &host);
// A number the rig's source states for `key`, else its plugin's default; 0 when neither says.
double sourceFigure(const YAML::Node &rig, const std::string &key, const PluginHost &host);
// The default of the plugin setting a rig path names ("source.camera_height_mm",
// "transforms.0.inclination_deg"), when that setting has a numeric default.
std::optional<double> settingDefault(const YAML::Node &rig, const std::string &path, const PluginHost &host);
// The lens of the lens table with this focal length, or nullptr.
const Lens *lensFor(const Experiment &e, double focal_length_mm);
// The node at a dotted rig path ("source.range_mm", "transforms.0.inclination_deg"), or
// an undefined node.
YAML::Node nodeAt(const YAML::Node &root, const std::string &path);
// Warns once for a variable the tests vary that goes nowhere in the rig.
void warnUnbound(const Experiment &e);

} // namespace binocle::experiment
