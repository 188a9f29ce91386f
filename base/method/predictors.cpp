// SPDX-License-Identifier: MIT
// Predictors of η3D from the design alone (FF, its band, disparity, depth resolution,
// a sensor-aware prediction of Eq. 2-6).
#include "method/predictors.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace binocle::method {

namespace {

// Share of [lo, hi] outside [fieldLo, fieldHi], 0..1; 0 when the field is unknown (NaN).
double outside(double lo, double hi, double fieldLo, double fieldHi) {
    if (!(hi > lo)) return 0;
    if (!std::isfinite(fieldLo) || !std::isfinite(fieldHi)) return 0;
    const double seen = std::max(0.0, std::min(hi, fieldHi) - std::max(lo, fieldLo));
    return 1.0 - seen / (hi - lo);
}

// Points lower than this are ground, not objects (the paper evaluator's ground_band_mm).
constexpr double kGroundBandMm = 200;

} // namespace

double predictedEta3d(const StereoDesign &design, const DesignFigures &f, const PanelPlacement &panel) {
    if (std::isfinite(f.min_range_mm) && f.range_mm < f.min_range_mm) return 0; // beyond the search: no panel
    const double pixelMm = f.range_mm * design.pixel_pitch_um * 1e-3 / design.focal_length_mm; // footprint at R
    const double epsY = 100.0 * f.depth_resolution_mm / f.range_mm;
    const double left = panel.center_x_mm - panel.width_mm / 2, right = panel.center_x_mm + panel.width_mm / 2;
    // Clutter: the ground's height noise at R (its depth noise seen along a ray that
    // falls hc / R) lifts ground points out of the ground band into the panel's range
    // band, across the whole stereo field; the share of the field it fills ramps from 0
    // when that noise is a quarter of the band to 1 at half of it.
    const double groundNoiseMm = design.camera_height_mm * f.depth_resolution_mm / f.range_mm;
    const double clutter = std::clamp(4.0 * groundNoiseMm / kGroundBandMm - 1.0, 0.0, 1.0);
    const double epsX = 100.0 * 2 * pixelMm / panel.width_mm + epsY / 2 +
                        100.0 * outside(left, right, f.stereo_field_min_x_mm, f.stereo_field_max_x_mm) +
                        100.0 * clutter * std::max(0.0, f.stereo_field_width_mm - panel.width_mm) / panel.width_mm;
    const double epsZ = 100.0 * 2 * pixelMm / panel.height_mm +
                        100.0 * outside(panel.base_z_mm, panel.base_z_mm + panel.height_mm, f.field_bottom_z_mm, f.field_top_z_mm);
    return std::clamp(100.0 - (epsX + epsY + epsZ) / 3, 0.0, 100.0);
}

PredictorValues predictors(const StereoDesign &design, double range_mm, const PanelPlacement &panel, double matching_error_px) {
    const DesignFigures f = designFigures(design, range_mm, matching_error_px, &panel);
    PredictorValues v;
    v.form_factor = f.form_factor;
    v.ff_band = -formFactorBandDistance(f.form_factor);
    v.expected_disparity = f.disparity_px;
    v.depth_resolution = -f.depth_resolution_mm / range_mm;
    v.sensor_aware = predictedEta3d(design, f, panel);
    return v;
}

const std::vector<std::string> &predictorNames() {
    static const std::vector<std::string> names = {"form_factor", "ff_band", "expected_disparity", "depth_resolution",
                                                   "sensor_aware"};
    return names;
}

double PredictorValues::get(const std::string &name) const {
    if (name == "form_factor") return form_factor;
    if (name == "ff_band") return ff_band;
    if (name == "expected_disparity") return expected_disparity;
    if (name == "depth_resolution") return depth_resolution;
    if (name == "sensor_aware") return sensor_aware;
    throw std::invalid_argument("unknown predictor '" + name + "'");
}

} // namespace binocle::method
