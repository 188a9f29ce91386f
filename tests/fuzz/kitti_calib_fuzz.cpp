// SPDX-License-Identifier: MIT
// Fuzz harness: the replay source's reader of KITTI calibration files (P2/P3 or
// P_rect_02/P_rect_03, S_rect_02).
#include "replay_metadata.hpp"

#include <binocle/plugin.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string text(reinterpret_cast<const char *>(data), size);
    try {
        const auto c = binocle::replay::parseKittiCalib(text, "calib_cam_to_cam.txt", 2, 3);
        if (c && (!(c->baselineMm > 0) || !std::isfinite(c->baselineMm) || !(c->left(0, 0) > 0))) std::abort();
    } catch (const binocle::sdk::Error &) {
    }
    return 0;
}
