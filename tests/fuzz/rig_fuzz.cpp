// SPDX-License-Identifier: MIT
// Fuzz harness: the rig loader with --set overrides (framework/config). The input is a
// rig's YAML text, optionally followed by a line "#--set" and one KEY=VALUE per line.
// A binocle::Error is the expected answer to bad input; anything else (another
// exception, a crash, a sanitizer finding) is a bug.
#include "config/rig_config.hpp"
#include "core/error.hpp"

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>

namespace {

binocle::PluginHost &host() {
    static std::unique_ptr<binocle::PluginHost> h = [] {
        ::setenv("BINOCLE_PLUGIN_PATH", BINOCLE_BUILD_PLUGIN_DIR, 0);
        auto p = std::make_unique<binocle::PluginHost>();
        p->scan();
        return p;
    }();
    return *h;
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    host();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string input(reinterpret_cast<const char *>(data), size);
    const size_t split = input.find("\n#--set\n");
    const std::string rig = input.substr(0, split);
    std::vector<binocle::Override> overrides;
    try {
        if (split != std::string::npos) {
            std::istringstream lines(input.substr(split + 8));
            for (std::string line; std::getline(lines, line);) overrides.push_back(binocle::Override::parse(line));
        }
        binocle::loadRigText(rig, "/fuzz/rig.yaml", overrides, host());
    } catch (const binocle::Error &) {
    }
    return 0;
}
