// SPDX-License-Identifier: MIT
// `binocle devices`: what each source plugin can see (cameras, heads), as YAML.
#include "cli/command.hpp"
#include "core/error.hpp"
#include "host/plugin_host.hpp"

#include <iostream>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

namespace binocle::cli {
namespace {

// The plugin's YAML list, indented under its name; a non-list answer is an error.
std::string indentedList(const std::string &yaml) {
    YAML::Node n = YAML::Load(yaml);
    if (n.IsNull() || (n.IsSequence() && n.size() == 0)) return "  devices: []\n";
    if (!n.IsSequence()) throw Error("the plugin answered something other than a YAML list: " + yaml);
    YAML::Emitter e;
    e << n;
    std::string out = "  devices:\n";
    std::string line;
    for (char c : std::string(e.c_str()) + "\n") {
        if (c != '\n') {
            line += c;
            continue;
        }
        if (!line.empty()) out += "    " + line + "\n";
        line.clear();
    }
    return out;
}

int listDevices(const std::string &plugin) {
    PluginHost host;
    host.scan(ScanMode::Isolated); // a source that crashes at load is refused, not fatal
    std::vector<const PluginRecord *> sources;
    if (!plugin.empty()) {
        sources.push_back(&host.require(plugin, BINOCLE_KIND_STEREO_SOURCE));
    } else {
        for (const auto &p : host.plugins())
            if (p.kind == BINOCLE_KIND_STEREO_SOURCE) sources.push_back(&p);
    }
    if (sources.empty()) {
        std::cout << "# no source plugin found\n";
        return 1;
    }
    int failures = 0;
    for (const PluginRecord *p : sources) {
        std::cout << p->name << ":\n";
        try {
            std::cout << indentedList(Source::enumerateDevices(*p)) << std::flush;
        } catch (const std::exception &e) {
            ++failures;
            YAML::Emitter message;
            message << std::string(e.what());
            std::cout << "  error: " << message.c_str() << "\n" << std::flush;
            spdlog::error("{}: {}", p->name, e.what());
        }
    }
    return failures == 0 ? 0 : 1;
}

Register devicesCommand{{"devices", "list the devices each source plugin can see (cameras, stereo heads)",
              "Asks every source plugin (or only NAME) which devices it can open and prints\n"
              "them as YAML, one key per plugin:\n"
              "  gige:\n"
              "    devices:\n"
              "      - id: Aravis-Fake-GV01\n"
              "        description: ...\n"
              "A plugin that fails is listed with `error:` and the others are still asked;\n"
              "the exit status is then 1. Plugins that talk to networks (gige) send discovery\n"
              "broadcasts on every interface.",
              define<std::string>(
                  [](CLI::App &app, std::string &plugin) {
                      app.add_option("--plugin", plugin, "ask this source plugin only")->type_name("NAME");
                  },
                  listDevices)}};

} // namespace
} // namespace binocle::cli
