// SPDX-License-Identifier: MIT
// A plugin's settings: the values an instance is made with (ParamValues), and the check
// of the table a plugin declares them in. How a rig reads them: framework/config.
#pragma once

#include <binocle/abi.h>

#include <memory>
#include <string>
#include <vector>

namespace binocle {

// Why a settings table is unusable ("setting #2 'window_px': default '4' is not odd"),
// or "" when every setting has a valid name, type and default, and names are unique.
std::string settingsTableProblem(const binocle_param_desc *params, int32_t count);

// Settings as the plugin receives them; owns the strings. How the instance runs
// (IsolationOptions, host/plugin_instance.hpp) is not a setting: it is given to the
// instance beside them.
class ParamValues {
public:
    void setBool(const std::string &name, bool v, bool isExplicit = true);
    void setInt(const std::string &name, int64_t v, bool isExplicit = true);
    void setDouble(const std::string &name, double v, bool isExplicit = true);
    // STRING, ENUM, PATH, YAML, lists: `type` is the desc's type.
    void setText(const std::string &name, int32_t type, const std::string &v, bool isExplicit = true);
    const binocle_param *data() const;
    int32_t size() const;
    const binocle_param *find(const std::string &name) const;

private:
    std::vector<binocle_param> values_;
    std::vector<std::shared_ptr<std::string>> strings_; // shared: copies keep pointers valid
    binocle_param &slot(const std::string &name);
};

} // namespace binocle
