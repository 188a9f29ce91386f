// SPDX-License-Identifier: MIT
// Design figures of a stereo head before any hardware is assembled: the form factor
// (METHOD.md Eq. 7) and the sensor-aware figures reported beside it.
#pragma once

namespace binocle::method {

// The figures of the paper (METHOD.md), in one place: `design` and `experiment` read them.
struct FormFactorBand {
    double min, max;
};
// Eq. 7's best band: the configurations of E1 with the best η3D.
inline constexpr FormFactorBand kBestFormFactorBand{1.2, 2.0};
// Below this FF a configuration reads "low", up to the best band "fair".
inline constexpr double kFairFormFactorMin = 1.0;
// The paper's Videre head as its experiments used it (images decimated by 4): the
// effective pixel pitch, the image size and its lens set.
inline constexpr double kViderePixelPitchUm = 20.8;
inline constexpr int kVidereImageWidthPx = 320, kVidereImageHeightPx = 240;
inline constexpr const char *kVidereLensesMm = "2.8,4,8,12,16";
// Δd: the matching error (px) the depth resolution is quoted for, everywhere (design,
// experiments, the paper evaluator's default): a quarter pixel, what a sub-pixel
// matcher such as SGBM resolves on a textured panel.
inline constexpr double kMatchingErrorPx = 0.25;
// hc when nobody says: the paper's vehicle carries its head 1.5 m above the ground.
inline constexpr double kDefaultCameraHeightMm = 1500;
// The matcher's search `design` assumes when not told (the E1 rig's SGBM: 64 from 0).
inline constexpr int kDefaultNumDisparities = 64;

// How far FF lies from the best band (0 inside), in log terms so that 0.6 and 4.0 (both
// a factor 2 off) weigh alike.
double formFactorBandDistance(double ff);

// Eq. 7: FF = 10 * B * f / R, with baseline B, focal length f and range R all in mm.
double formFactor(double baseline_mm, double focal_length_mm, double range_mm);
// Eq. 7 solved for f: the focal length (mm) that gives form factor `ff` at range R.
double focalLengthForFormFactor(double ff, double baseline_mm, double range_mm);
// METHOD.md's reading of FF: "low" (< 1.0), "fair" (1.0-1.2), "best" (1.2-2.0), "high" (> 2.0).
const char *formFactorReading(double ff);

// Disparity law: d = B * f / (R * p) pixels, with the pixel pitch p in um.
double expectedDisparityPx(double baseline_mm, double focal_length_mm, double range_mm, double pixel_pitch_um);
// Depth resolution: dR = R^2 * p * dd / (B * f) mm for a matching error dd (px).
double depthResolutionMm(double baseline_mm, double focal_length_mm, double range_mm, double pixel_pitch_um,
                         double matching_error_px);
// Nearest range the matcher can see: a search over disparities min_d .. min_d + N - 1
// finds at most d_max = min_d + N - 1, so R_min = B * f / (p * d_max). NaN when
// d_max < 1 (no search known).
double minimumRangeMm(double baseline_mm, double focal_length_mm, double pixel_pitch_um, int min_disparity_px,
                      int num_disparities);
// Angle a row (or column) of `pixels` pixels of pitch p sees: 2 * atan(N * p / (2 f)), degrees.
double fieldOfViewDeg(int pixels, double pixel_pitch_um, double focal_length_mm);
// Width the same pixels cover at range R (mm): R * N * p / f.
double fieldWidthMm(double range_mm, int pixels, double pixel_pitch_um, double focal_length_mm);

// The head description: a stereo head, what Eq. 7 and the figures need. One struct for
// `design`, experiments and the paper evaluator. Lengths in mm, pitch in um.
struct StereoDesign {
    double baseline_mm = 0;
    double focal_length_mm = 0;
    double pixel_pitch_um = 0;    // effective pitch of an image pixel (after decimation)
    int image_width_px = 0, image_height_px = 0;
    int min_disparity_px = 0;     // the matcher's search; num_disparities 0 = unknown
    int num_disparities = 0;
    double camera_height_mm = kDefaultCameraHeightMm; // hc and theta of Eq. 1, for the vertical field
    double inclination_deg = 0;

    double focalLengthPx() const { return focal_length_mm * 1000.0 / pixel_pitch_um; }
    // The same sensor and matcher in one configuration: baseline, lens, camera height
    // and inclination (a test of an experiment, a candidate of `design`).
    StereoDesign configured(double baseline, double focal_length, double camera_height, double inclination) const {
        StereoDesign d = *this;
        d.baseline_mm = baseline;
        d.focal_length_mm = focal_length;
        d.camera_height_mm = camera_height;
        d.inclination_deg = inclination;
        return d;
    }
};

// The paper's Videre head as its experiments used it (no baseline or lens yet), with the
// E1 rig's disparity search.
inline StereoDesign videreHead() {
    StereoDesign d;
    d.pixel_pitch_um = kViderePixelPitchUm;
    d.image_width_px = kVidereImageWidthPx;
    d.image_height_px = kVidereImageHeightPx;
    d.num_disparities = kDefaultNumDisparities;
    return d;
}

// A test panel standing in the field of view (ground frame, mm).
struct PanelPlacement {
    double width_mm = 2500, height_mm = 2000;
    double center_x_mm = 0; // lateral position of its middle
    double base_z_mm = 0;   // height of its lower edge
};

struct DesignFigures {
    double range_mm = 0;
    double form_factor = 0;           // Eq. 7
    double disparity_px = 0;          // d at R
    double matching_error_px = 0;     // dd used for depth_resolution_mm
    double depth_resolution_mm = 0;   // dR at R
    double min_range_mm = 0;          // NaN when the search is unknown
    double horizontal_fov_deg = 0, vertical_fov_deg = 0; // NaN when the image size is unknown
    double field_width_mm = 0;        // what the left imager covers at R
    // Lateral band at R seen by both imagers and searched by the matcher: the left
    // imager's field less max(B, the search's blind columns at R) on the left.
    double stereo_field_min_x_mm = 0, stereo_field_max_x_mm = 0;
    double stereo_field_width_mm = 0;
    double field_bottom_z_mm = 0, field_top_z_mm = 0; // heights the left imager sees at R
    // With a panel: does it fit, and which part of the stereo field it fills.
    bool panel_given = false;
    bool panel_fits_width = false, panel_fits_height = false;
    double panel_width_ratio = 0;     // panel width / stereo field width
    double panel_height_ratio = 0;    // panel height / field height at R
};

// All figures of `design` at range R. Values that need a missing input (image size,
// disparity search) are NaN. Throws std::invalid_argument when B, f, p or R is not positive.
DesignFigures designFigures(const StereoDesign &design, double range_mm, double matching_error_px = kMatchingErrorPx,
                            const PanelPlacement *panel = nullptr);

} // namespace binocle::method
