// SPDX-License-Identifier: MIT
// What `binocle calibrate` writes: the calibration file named after the configuration
// (calib_B150_f8.yml), ROS camera_info YAML for each camera, and the JSON report.
#pragma once

#include "core/calibration.hpp"
#include "core/json.hpp"

#include <optional>
#include <string>

namespace binocle {

// "B150_f8": baseline rounded to the mm, focal length to 0.1 mm ("f2.8"); without a
// focal length in mm, the focal length in px ("B75_f532px").
std::string configurationName(double baseline_mm, std::optional<double> focal_length_mm, double focal_length_px);

// ROS camera_info YAML (camera_calibration_parsers' format, plumb_bob) of the left or the
// right camera: K, D, the rectification R1/R2 and the projection P1/P2. The projection's
// translation is in metres there (ROS, REP 103), unlike the millimetres of Binocle files.
std::string cameraInfoYaml(const StereoCalibration &calibration, bool right, const std::string &cameraName);

// The files of one calibration, all beside `calibration`: <stem>_left.yaml,
// <stem>_right.yaml (camera_info), <stem>_report.json.
struct CalibrationFiles {
    std::string calibration, left_info, right_info, report;
    static CalibrationFiles beside(const std::string &calibrationPath);
};

// Writes them all, each atomically; the calibration file last, so that its presence
// means the others are complete. When a write fails (a full disk) the files written
// before it are removed again and the error says so. Creates the folder when needed.
void writeCalibrationFiles(const CalibrationFiles &files, const StereoCalibration &calibration, const Json &report);

} // namespace binocle
