// SPDX-License-Identifier: MIT
// Form factor (Eq. 7) and the sensor-aware design figures.
#include "method/design.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace binocle::method {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;
double deg(double rad) { return rad * 180.0 / kPi; }
double rad(double deg) { return deg * kPi / 180.0; }

void requirePositive(double v, const char *name) {
    if (!(v > 0) || !std::isfinite(v)) {
        std::ostringstream s;
        s << name << " = " << v << ": expected a positive number";
        throw std::invalid_argument(s.str());
    }
}
} // namespace

// Eq. 7: FF = 10 B f / R (B, f, R in mm).
double formFactor(double baseline_mm, double focal_length_mm, double range_mm) {
    return 10.0 * baseline_mm * focal_length_mm / range_mm;
}

double focalLengthForFormFactor(double ff, double baseline_mm, double range_mm) {
    return ff * range_mm / (10.0 * baseline_mm);
}

const char *formFactorReading(double ff) {
    if (!std::isfinite(ff)) return "unknown";
    if (ff < kFairFormFactorMin) return "low";
    if (ff < kBestFormFactorBand.min) return "fair";
    if (ff <= kBestFormFactorBand.max) return "best";
    return "high";
}

double formFactorBandDistance(double ff) {
    const auto [lo, hi] = kBestFormFactorBand;
    if (ff >= lo && ff <= hi) return 0;
    return ff < lo ? std::log(lo / ff) : std::log(ff / hi);
}

// d = B f / (R p), p converted from um to mm.
double expectedDisparityPx(double baseline_mm, double focal_length_mm, double range_mm, double pixel_pitch_um) {
    return baseline_mm * focal_length_mm / (range_mm * pixel_pitch_um * 1e-3);
}

// dR = R^2 p dd / (B f): the derivative of R = B f / (d p) times the matching error.
double depthResolutionMm(double baseline_mm, double focal_length_mm, double range_mm, double pixel_pitch_um,
                         double matching_error_px) {
    return range_mm * range_mm * pixel_pitch_um * 1e-3 * matching_error_px / (baseline_mm * focal_length_mm);
}

double minimumRangeMm(double baseline_mm, double focal_length_mm, double pixel_pitch_um, int min_disparity_px,
                      int num_disparities) {
    const int dmax = min_disparity_px + num_disparities - 1;
    if (num_disparities <= 0 || dmax < 1) return kNaN;
    return baseline_mm * focal_length_mm / (pixel_pitch_um * 1e-3 * dmax);
}

double fieldOfViewDeg(int pixels, double pixel_pitch_um, double focal_length_mm) {
    if (pixels <= 0) return kNaN;
    return deg(2.0 * std::atan(pixels * pixel_pitch_um * 1e-3 / (2.0 * focal_length_mm)));
}

double fieldWidthMm(double range_mm, int pixels, double pixel_pitch_um, double focal_length_mm) {
    if (pixels <= 0) return kNaN;
    return range_mm * pixels * pixel_pitch_um * 1e-3 / focal_length_mm;
}

DesignFigures designFigures(const StereoDesign &d, double range_mm, double matching_error_px,
                            const PanelPlacement *panel) {
    requirePositive(d.baseline_mm, "baseline_mm");
    requirePositive(d.focal_length_mm, "focal_length_mm");
    requirePositive(d.pixel_pitch_um, "pixel_pitch_um");
    requirePositive(range_mm, "range_mm");
    DesignFigures f;
    f.range_mm = range_mm;
    f.form_factor = formFactor(d.baseline_mm, d.focal_length_mm, range_mm);
    f.disparity_px = expectedDisparityPx(d.baseline_mm, d.focal_length_mm, range_mm, d.pixel_pitch_um);
    f.matching_error_px = matching_error_px;
    f.depth_resolution_mm = depthResolutionMm(d.baseline_mm, d.focal_length_mm, range_mm, d.pixel_pitch_um,
                                              matching_error_px);
    f.min_range_mm = minimumRangeMm(d.baseline_mm, d.focal_length_mm, d.pixel_pitch_um, d.min_disparity_px,
                                    d.num_disparities);
    f.horizontal_fov_deg = fieldOfViewDeg(d.image_width_px, d.pixel_pitch_um, d.focal_length_mm);
    f.vertical_fov_deg = fieldOfViewDeg(d.image_height_px, d.pixel_pitch_um, d.focal_length_mm);
    f.field_width_mm = fieldWidthMm(range_mm, d.image_width_px, d.pixel_pitch_um, d.focal_length_mm);

    // Lateral field at R (principal point in the middle of the image). The right imager
    // sees the left's field shifted by B; the matcher cannot match the leftmost
    // min_d + N - 1 columns, which cover (min_d + N - 1) p R / f at R.
    const double mmPerPxAtR = range_mm * d.pixel_pitch_um * 1e-3 / d.focal_length_mm;
    const int dmax = d.num_disparities > 0 ? d.min_disparity_px + d.num_disparities - 1 : 0;
    const double blind = std::max(d.baseline_mm, dmax * mmPerPxAtR);
    f.stereo_field_min_x_mm = -f.field_width_mm / 2 + blind;
    f.stereo_field_max_x_mm = f.field_width_mm / 2;
    f.stereo_field_width_mm = std::max(0.0, f.stereo_field_max_x_mm - f.stereo_field_min_x_mm);

    // Vertical field at horizontal distance R: rays pitched theta +- vfov/2 below the horizon.
    if (std::isfinite(f.vertical_fov_deg)) {
        const double theta = rad(d.inclination_deg), half = rad(f.vertical_fov_deg) / 2;
        f.field_top_z_mm = d.camera_height_mm - range_mm * std::tan(theta - half);
        f.field_bottom_z_mm = theta + half >= kPi / 2 ? -std::numeric_limits<double>::infinity()
                                                      : d.camera_height_mm - range_mm * std::tan(theta + half);
    } else {
        f.field_top_z_mm = f.field_bottom_z_mm = kNaN;
    }

    if (panel) {
        f.panel_given = true;
        const double left = panel->center_x_mm - panel->width_mm / 2, right = panel->center_x_mm + panel->width_mm / 2;
        f.panel_fits_width = std::isfinite(f.field_width_mm) && left >= f.stereo_field_min_x_mm &&
                             right <= f.stereo_field_max_x_mm;
        f.panel_fits_height = std::isfinite(f.field_top_z_mm) && panel->base_z_mm >= f.field_bottom_z_mm &&
                              panel->base_z_mm + panel->height_mm <= f.field_top_z_mm;
        f.panel_width_ratio = f.stereo_field_width_mm > 0 ? panel->width_mm / f.stereo_field_width_mm : kNaN;
        const double fieldHeight = f.field_top_z_mm - f.field_bottom_z_mm;
        f.panel_height_ratio = std::isfinite(fieldHeight) && fieldHeight > 0 ? panel->height_mm / fieldHeight : kNaN;
    }
    return f;
}

} // namespace binocle::method
