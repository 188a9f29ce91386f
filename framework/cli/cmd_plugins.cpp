// SPDX-License-Identifier: MIT
// `binocle plugins`: what the host found, with versions, and what it refused and why.
#include "cli/command.hpp"
#include "host/plugin_host.hpp"

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace binocle::cli {
namespace {

struct PluginsArgs {
    bool verbose = false;
    std::vector<std::string> load;
    long long timeout_ms = 5000;
};

// "int, odd, >= 1, <= 255", "enum bm|sgbm", "required": what --verbose shows of a setting.
std::string constraints(const binocle_param_desc &d) {
    static const char *types[] = {"?", "bool", "int", "double", "string", "enum", "path", "yaml", "int list", "double list"};
    std::ostringstream os;
    os << types[(d.type >= 1 && d.type <= 9) ? d.type : 0];
    if (d.type == BINOCLE_PARAM_ENUM && d.choices) os << " " << d.choices;
    if (d.flags & BINOCLE_PARAM_FLAG_ODD) os << ", odd";
    if (d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) os << ", >= " << d.min;
    if (d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) os << ", <= " << d.max;
    if (d.multiple_of > 0) os << ", multiple of " << d.multiple_of;
    if (d.flags & BINOCLE_PARAM_FLAG_REQUIRED) os << ", required";
    return os.str();
}

int listPlugins(const PluginsArgs &args) {
    PluginHost host;
    for (const auto &p : args.load) host.load(p);
    // Each file is opened in a short-lived child first: one that crashes or hangs at load
    // is listed as refused, and the listing goes on.
    host.scan(ScanMode::Isolated, static_cast<int32_t>(args.timeout_ms));
    std::cout << "search path:\n";
    for (const auto &d : host.searchPath()) std::cout << "  " << d << "\n";
    std::cout << "\nplugins (host ABI " << BINOCLE_ABI_VERSION << ", API " << BINOCLE_API_VERSION << "):\n";
    if (host.plugins().empty()) std::cout << "  none\n";
    size_t nameWidth = 12;
    for (const auto &p : host.plugins()) nameWidth = std::max(nameWidth, p.name.size() + 2);
    for (const auto &p : host.plugins()) {
        std::cout << "  " << std::left << std::setw(static_cast<int>(nameWidth)) << p.name << std::setw(10) << kindName(p.kind) << std::setw(9)
                  << p.version << "ABI " << p.abi_version << " API " << p.api_version << "  " << p.description << "\n";
        if (args.verbose) {
            std::cout << "      file: " << p.path << "\n";
            for (const auto &d : p.params())
                std::cout << "      " << std::setw(24) << d.name << (d.default_value ? d.default_value : "(required)")
                          << (d.unit && *d.unit ? std::string(" ") + d.unit : "") << "  [" << constraints(d) << "]  "
                          << (d.help ? d.help : "") << "\n";
        }
    }
    if (!host.refused().empty()) {
        std::cout << "\nrefused:\n";
        for (const auto &r : host.refused()) std::cout << "  " << r.path << ": " << r.reason << "\n";
    }
    return 0;
}

Register pluginsCommand{{"plugins", "list the plugins found, with versions, and those refused and why",
              "Lists every plugin in the search path ($BINOCLE_PLUGIN_PATH, then the install\n"
              "prefix next to this executable) with its kind, version and ABI/API versions, and\n"
              "every file or folder that was refused with the reason. Each file is first opened\n"
              "in a short-lived child process: one that crashes or hangs while loading is\n"
              "refused with the signal or the timeout.",
              define<PluginsArgs>(
                  [](CLI::App &app, PluginsArgs &args) {
                      app.add_flag("--verbose", args.verbose,
                                   "also show each plugin's file and settings (YAML keys) with type, choices, odd, "
                                   "min/max, multiple-of and required");
                      app.add_option("--load", args.load, "load this plugin file as well (repeatable)")
                          ->type_name("FILE")
                          ->allow_extra_args(false);
                      app.add_option("--timeout-ms", args.timeout_ms, "how long a file may take to load (default 5000)")
                          ->check(atLeast(100));
                  },
                  listPlugins)}};

} // namespace
} // namespace binocle::cli
