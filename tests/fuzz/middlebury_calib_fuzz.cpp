// SPDX-License-Identifier: MIT
// Fuzz harness: the replay source's reader of Middlebury calib.txt.
#include "replay_metadata.hpp"

#include <binocle/plugin.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string text(reinterpret_cast<const char *>(data), size);
    try {
        const auto c = binocle::replay::parseMiddleburyCalib(text, "calib.txt");
        if (!(c.cam0[0] > 0) || !(c.baselineMm > 0) || !std::isfinite(c.baselineMm) || c.width < 0) std::abort();
    } catch (const binocle::sdk::Error &) {
    }
    return 0;
}
