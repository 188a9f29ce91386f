// SPDX-License-Identifier: MIT
// Predictors of the stereo efficiency η3D known before any hardware is assembled: the
// form factor (Eq. 7), the paper's best FF band, the expected disparity, the depth
// resolution, and a sensor-aware prediction of η3D. Each is a score where higher
// should mean a better configuration, so that Spearman's rho with measured η3D says
// how well it ranks (1: perfectly, 0: not at all, < 0: backwards).
#pragma once

#include "method/design.hpp"

#include <string>
#include <vector>

namespace binocle::method {

// The sensor-aware prediction of η3D (%), Eq. 2-6 with each relative error estimated
// from the design alone:
//   εy ≈ 100 ΔR / R                 (depth resolution for the matching error dd)
//   εx ≈ 100 (2 R p / f) / W + εy/2 + 100 (share of W outside the stereo field)
//        + 100 c (stereo field width - W) / W
//        with c = clamp(4 σz / 200 mm - 1, 0, 1) the share of the field the ground's
//        clutter fills: σz = hc ΔR / R, the ground's height noise at R, against the
//        200 mm ground band of the panel reading (the ramp's ends were chosen from the
//        failures of the simulated E1: a prediction fitted in-sample, see its rho)
//   εz ≈ 100 (2 R p / f) / H + 100 (share of H outside the vertical field)
// (two pixels' footprint for the two edges an extent is read between; a width read in
// mm carries the depth error through X = u Z / f); 0 when the panel lies nearer than the
// matcher's search reaches. `figures` must come from designFigures(design, R, dd, &panel).
double predictedEta3d(const StereoDesign &design, const DesignFigures &figures, const PanelPlacement &panel);

// The predictors by name, in the order they are reported.
const std::vector<std::string> &predictorNames(); // form_factor, ff_band, expected_disparity, depth_resolution, sensor_aware

struct PredictorValues {
    double form_factor = 0;         // FF (Eq. 7)
    double ff_band = 0;             // -formFactorBandDistance(FF)
    double expected_disparity = 0;  // d, px
    double depth_resolution = 0;    // -ΔR / R: a smaller relative depth step is better
    double sensor_aware = 0;        // predictedEta3d
    double get(const std::string &name) const; // by predictorNames(); throws on an unknown name
};

PredictorValues predictors(const StereoDesign &design, double range_mm, const PanelPlacement &panel,
                           double matching_error_px = kMatchingErrorPx);

} // namespace binocle::method
