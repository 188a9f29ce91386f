// SPDX-License-Identifier: MIT
// Calibration mode of the `sim` source: a chessboard held in varied poses in front of
// the rig, one pose per frame, for `binocle calibrate` and its tests.
#pragma once

#include "rig.hpp"
#include "scene.hpp"

#include <cstdint>
#include <string>

namespace binocle::sim {

struct BoardSettings {
    int cols = 9, rows = 6;      // inner corners per row / per column (cv::findChessboardCorners)
    double square_mm = 25;
    int poses = 12;              // frames before end of stream; 0: endless (the caller takes what it needs)
    double max_tilt_deg = 30;    // largest rotation of the board about its horizontal and vertical axes
    uint32_t seed = 1;

    // From the YAML text of the calibration_board setting ({cols, rows, square_mm, poses,
    // max_tilt_deg, seed}); throws SceneError naming the key.
    static BoardSettings fromYaml(const std::string &text);
};

// The scene of pose `index`: the board (a thin box named "board", its chessboard on the
// face towards the rig, a one-square white margin) in front of the left imager, seen
// whole by both imagers, on a uniform grey background.
Scene boardScene(const BoardSettings &board, const StereoRig &rig, int index);

} // namespace binocle::sim
