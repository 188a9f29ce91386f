// SPDX-License-Identifier: MIT
// The plugins the benchmarks load, each set scanned once a run.
#pragma once

#include "host/plugin_host.hpp"

namespace binocle::bench {

// The plugins built with Binocle (BINOCLE_BUILD_PLUGIN_DIR).
const PluginHost &builtPlugins();
// Those and the plugins only the benchmarks load (BINOCLE_BENCH_PLUGIN_DIR).
const PluginHost &builtAndBenchPlugins();

} // namespace binocle::bench
