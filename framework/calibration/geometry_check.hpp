// SPDX-License-Identifier: MIT
// The geometry check run before the first frame: a calibration is refused when its image
// size, its baseline's sign or its baseline's magnitude disagree with the rig.
#pragma once

#include "config/rig_config.hpp"
#include "core/calibration.hpp"

#include <optional>
#include <string>
#include <vector>

namespace binocle {

struct GeometryExpectation {
    cv::Size image_size;                // what the source delivers
    std::optional<double> baseline_mm;  // what the rig states (its source's baseline_mm), if anything
    std::string source;                 // source plugin name, for the messages
    double baseline_tolerance = 0.05;   // relative: |T| may differ from baseline_mm by this share
};

// One sentence per disagreement, each naming `origin` (the calibration file, or "the
// calibration published by source 'x'"); empty when the calibration fits.
std::vector<std::string> geometryDisagreements(const StereoCalibration &calibration, const GeometryExpectation &expected,
                                               const std::string &origin);

// Throws binocle::Error with every disagreement.
void checkGeometry(const StereoCalibration &calibration, const GeometryExpectation &expected, const std::string &origin);

// What a rig states about its head, from its source block's settings where the source
// plugin has them (the sim's baseline_mm, focal_length_mm, pixel_pitch_um).
struct StatedGeometry {
    std::optional<double> baseline_mm, focal_length_mm, pixel_pitch_um;
};
StatedGeometry statedGeometry(const PluginBlock &source);

} // namespace binocle
