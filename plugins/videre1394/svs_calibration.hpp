// SPDX-License-Identifier: MIT
// videre1394: the calibration a Videre head stores (SVS parameter text) read into the
// calibration format of framework/core/calibration.hpp (OpenCV FileStorage YAML).
//
// The SVS text is .ini-like: "[section]" lines, then "key value" lines; matrices ("proj",
// "rect") continue on lines of numbers only. What is read:
//   [left camera], [right camera]  pwidth pheight  f fy Cx Cy (px)  kappa1 kappa2 kappa3
//                                  tau1 tau2 (radial and tangential distortion)
//   [external]                     Tx Ty Tz (mm), Rx Ry Rz (rad): the right camera
//                                  relative to the left
//   [image]                        width height (when pwidth/pheight are absent)
// Everything else (stereo engine settings, SVS's own rectification) is ignored.
#pragma once

#include <string>

namespace binocle::videre1394 {

struct SvsCamera {
    double width = 0, height = 0; // image size the camera was calibrated at (px)
    double f = 0, fy = 0;         // focal length in px (fy: 0 = same as f)
    double cx = 0, cy = 0;        // principal point (px)
    double kappa1 = 0, kappa2 = 0, kappa3 = 0, tau1 = 0, tau2 = 0;
};

struct SvsCalibration {
    SvsCamera left, right;
    double tx = 0, ty = 0, tz = 0; // mm
    double rx = 0, ry = 0, rz = 0; // rad
};

// Throws std::invalid_argument naming the line, section and key that are wrong or missing.
SvsCalibration parseSvs(const std::string &text);

// The calibration for images of width x height (the head's images after decimation):
// focal lengths and principal points scale with the image, distortion does not.
// - Distortion: D = [kappa1, kappa2, tau1, tau2, kappa3] (OpenCV's k1, k2, p1, p2, k3).
// - Extrinsics in OpenCV's sense, x_right = R x_left + T: T = [Tx, Ty, Tz] mm and
//   R = Rodrigues([Rx, Ry, Rz]). SVS files give Tx < 0 for a right camera to the right,
//   as OpenCV's T does; baseline_mm = |T|.
// Throws std::invalid_argument when width x height is not a scaling of the calibrated size.
std::string calibrationYaml(const SvsCalibration &svs, int width, int height, const std::string &configuration);

} // namespace binocle::videre1394
