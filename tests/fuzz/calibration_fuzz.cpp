// SPDX-License-Identifier: MIT
// Fuzz harness: the stereo calibration reader (framework/core/calibration.cpp), from
// OpenCV FileStorage YAML text to a validated, rectified calibration. binocle::Error is
// the expected answer to bad input.
#include "core/calibration.hpp"
#include "core/error.hpp"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string text(reinterpret_cast<const char *>(data), size);
    try {
        const auto c = binocle::StereoCalibration::fromYaml(text, "fuzz.yml");
        // What the pipeline relies on once a calibration is accepted.
        if (!(c.focalLengthPx() > 0) || !std::isfinite(c.focalLengthPx()) || !(c.baselineMm() > 0) ||
            !std::isfinite(c.baselineMm()))
            std::abort();
    } catch (const binocle::Error &) {
    }
    return 0;
}
