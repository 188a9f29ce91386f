// SPDX-License-Identifier: MIT
// Calibration per configuration, as the paper did it: before a test runs, its source
// shows a chessboard in about ten poses, the project's stereo calibrator
// (framework/calibration) calibrates the pair from them, and the test runs with that
// calibration instead of the one the source publishes.
#pragma once

#include "calibration/board.hpp"
#include "host/plugin_host.hpp"

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <string>
#include <utility>
#include <vector>

namespace binocle {

// The experiment's `board_calibration:` block.
struct BoardCalibrationSpec {
    int pairs = 10;       // chessboard pairs taken per configuration
    BoardSpec board{9, 6, 25};
    // Rig overrides (path -> YAML value) that make the test's source show the board:
    // the source's own keys, named by the experiment file, not by the framework.
    std::vector<std::pair<std::string, std::string>> capture;
    int max_frames = 0;   // frames read at most to get `pairs` usable ones; 0: 3 x pairs
};

// What calibrating one configuration gave.
struct BoardCalibrationOutcome {
    std::string file;              // the calibration file written
    int pairs_offered = 0, pairs_used = 0;
    double rms_px = NAN;           // stereo RMS reprojection error
    double baseline_mm = NAN, focal_length_px = NAN;
    // Against the calibration the source publishes (exact for a simulated head); NaN
    // when it publishes none.
    double true_baseline_mm = NAN, true_focal_length_px = NAN;
    double baseline_error_percent = NAN, focal_length_error_percent = NAN;
    nlohmann::ordered_json toJson() const;
};

// Renders (or acquires) the board pairs with `testRig` plus spec.capture, calibrates
// them and writes the calibration (and its report, camera_info files) as
// `calibrationFile` (pixelPitchUm <= 0: unknown, for the report). Throws binocle::Error naming the test's rig when the source ends
// early or too few pairs show the board.
BoardCalibrationOutcome calibrateConfiguration(const YAML::Node &testRig, const std::string &rigFile,
                                               const BoardCalibrationSpec &spec, const PluginHost &host,
                                               const std::string &calibrationFile, double pixelPitchUm);

} // namespace binocle
