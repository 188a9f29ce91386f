// SPDX-License-Identifier: MIT
// The plugins the benchmarks load (bench_plugins.hpp).
#include "bench_plugins.hpp"

#include <memory>
#include <string>
#include <vector>

namespace binocle::bench {
namespace {

std::unique_ptr<PluginHost> scannedPlugins(std::vector<std::string> folders) {
    auto host = std::make_unique<PluginHost>(std::move(folders));
    host->scan();
    return host;
}

} // namespace

const PluginHost &builtPlugins() {
    static const std::unique_ptr<PluginHost> host = scannedPlugins({BINOCLE_BUILD_PLUGIN_DIR});
    return *host;
}

const PluginHost &builtAndBenchPlugins() {
    static const std::unique_ptr<PluginHost> host = scannedPlugins({BINOCLE_BUILD_PLUGIN_DIR, BINOCLE_BENCH_PLUGIN_DIR});
    return *host;
}

} // namespace binocle::bench
