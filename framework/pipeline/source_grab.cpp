// SPDX-License-Identifier: MIT
// Taking pairs from a source: its `live` word and the sliced grab (source_grab.hpp).
#include "pipeline/source_grab.hpp"

#include <algorithm>
#include <chrono>
#include <yaml-cpp/yaml.h>

namespace binocle {

bool sourceIsLive(Source &source) {
    try {
        const std::string statistics = source.statistics();
        if (statistics.empty()) return false;
        const YAML::Node n = YAML::Load(statistics);
        return n.IsMap() && n["live"] && n["live"].as<bool>(false);
    } catch (const std::exception &) {
        return false;
    }
}

std::unique_ptr<LentFrame> grabWithin(Source &source, int32_t timeoutMs, const std::function<bool()> &stopped) {
    const auto t0 = std::chrono::steady_clock::now();
    auto elapsedMs = [&] {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    };
    for (;;) {
        const int32_t left = timeoutMs < 0 ? 250 : std::max<int32_t>(1, timeoutMs - static_cast<int32_t>(elapsedMs()));
        try {
            return source.grab(std::min<int32_t>(250, left));
        } catch (const PluginError &e) {
            if (e.code() != BINOCLE_ERR_TIMEOUT || (stopped && stopped())) throw;
            if (timeoutMs >= 0 && elapsedMs() >= timeoutMs) throw;
        }
    }
}

} // namespace binocle
