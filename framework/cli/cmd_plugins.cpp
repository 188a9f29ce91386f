// SPDX-License-Identifier: MIT
// `binocle plugins`: what the host found, with versions, and what it refused and why.
#include "cli/command.hpp"
#include "host/plugin_host.hpp"

#include <algorithm>
#include <iomanip>
#include <iostream>

namespace binocle::cli {
namespace {

struct PluginsArgs {
    bool verbose = false;
    std::vector<std::string> load;
};

int listPlugins(const PluginsArgs &args) {
    PluginHost host;
    for (const auto &p : args.load) host.load(p);
    host.scan();
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
                          << (d.unit && *d.unit ? std::string(" ") + d.unit : "") << "  " << (d.help ? d.help : "") << "\n";
        }
    }
    if (!host.refused().empty()) {
        std::cout << "\nrefused:\n";
        for (const auto &r : host.refused()) std::cout << "  " << r.path << ": " << r.reason << "\n";
    }
    return 0;
}

Register reg{{"plugins", "list the plugins found, with versions, and those refused and why",
              "Lists every plugin in the search path ($BINOCLE_PLUGIN_PATH, then the install\n"
              "prefix, then the build tree) with its kind, version and ABI/API versions, and\n"
              "every file that was refused with the reason.",
              [](CLI::App &app) -> Runner {
                  auto args = std::make_shared<PluginsArgs>();
                  app.add_flag("--verbose", args->verbose, "also show each plugin's file and settings (YAML keys)");
                  app.add_option("--load", args->load, "load this plugin file as well (repeatable)")
                      ->type_name("FILE")
                      ->allow_extra_args(false);
                  return [args] { return listPlugins(*args); };
              }}};

} // namespace
} // namespace binocle::cli
