// SPDX-License-Identifier: MIT
// The `binocle` command: subcommands register themselves, one file each (cmd_*.cpp).
#pragma once

#include "config/rig_config.hpp"

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace binocle::cli {

// Parsed command line of one subcommand: positionals, and --name value / --name=value
// options (repeatable ones keep every value).
class Args {
public:
    Args(std::vector<std::string> argv, const std::vector<std::string> &flags);
    const std::vector<std::string> &positional() const { return positional_; }
    bool has(const std::string &name) const { return options_.count(name) != 0; }
    std::string get(const std::string &name, const std::string &def = "") const;
    std::vector<std::string> all(const std::string &name) const;
    // Integer option; throws binocle::Error naming the option and the value.
    long long integer(const std::string &name, long long def) const;
    double real(const std::string &name, double def) const;

private:
    std::vector<std::string> positional_;
    std::multimap<std::string, std::string> options_;
};

struct Command {
    std::string name;
    std::string summary;                 // one line for `binocle --help`
    std::string help;                    // full text for `binocle <name> --help`
    std::vector<std::string> flags;      // options that take no value (e.g. "--simulate")
    std::function<int(const Args &)> run;
};

const std::map<std::string, Command> &commands();

// The rig named by the first positional argument, with every --set override applied,
// validated against the plugins `host` found.
RigConfig loadRigFromArgs(const Args &args, const PluginHost &host);

// A file shipped with Binocle (e.g. "configs/rigs/sim-e1.yaml"): from the install prefix
// next to the executable, else from the source tree it was built from.
std::string dataFile(const std::string &relative);

struct Register {
    explicit Register(Command c);
};

} // namespace binocle::cli
