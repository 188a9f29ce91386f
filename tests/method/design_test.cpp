// SPDX-License-Identifier: MIT
// Form factor (Eq. 7) and the sensor-aware design figures, against hand-computed values.
#include "method/design.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace binocle::method {
namespace {

// METHOD.md: the FF of Tests 1, 8, 9 and 13 of E1, to two decimals.
TEST(FormFactor, Eq7ReproducesThePapersTests) {
    struct Case { int test; double b, f, r, ff; };
    const Case cases[] = {{1, 100, 2.8, 6000, 0.47}, {8, 150, 12, 6000, 3.00}, {9, 150, 4, 12000, 0.50},
                          {13, 190, 4, 12000, 0.63}};
    for (const Case &c : cases) {
        const double ff = formFactor(c.b, c.f, c.r);
        EXPECT_DOUBLE_EQ(std::round(ff * 100) / 100, c.ff) << "test " << c.test << ": FF = " << ff;
    }
    EXPECT_NEAR(formFactor(100, 2.8, 6000), 0.4667, 1e-4);
    EXPECT_NEAR(focalLengthForFormFactor(formFactor(190, 8, 12000), 190, 12000), 8, 1e-12);
}

TEST(FormFactor, Reading) {
    EXPECT_STREQ(formFactorReading(0.47), "low");
    EXPECT_STREQ(formFactorReading(1.1), "fair");
    EXPECT_STREQ(formFactorReading(1.6), "best");
    EXPECT_STREQ(formFactorReading(3.0), "high");
    EXPECT_STREQ(formFactorReading(NAN), "unknown");
}

// B = 150 mm, f = 8 mm, p = 20.8 um (5.2 um decimated by 4), R = 6 m.
TEST(DesignFigures, DisparityLawAndDepthResolution) {
    EXPECT_NEAR(expectedDisparityPx(150, 8, 6000, 20.8), 1200.0 / (6000 * 0.0208), 1e-9); // 9.615 px
    EXPECT_NEAR(expectedDisparityPx(150, 8, 6000, 20.8), 9.6154, 1e-4);
    // dR = R^2 p dd / (B f) = 36e6 * 0.0208 * 1 / 1200 = 624 mm for one pixel.
    EXPECT_NEAR(depthResolutionMm(150, 8, 6000, 20.8, 1.0), 624.0, 1e-9);
    EXPECT_NEAR(depthResolutionMm(150, 8, 6000, 20.8, 0.25), 156.0, 1e-9);
    // Consistent with the disparity law: R(d - dd) - R(d) ~ dR for a small dd.
    const double d = expectedDisparityPx(150, 8, 6000, 20.8);
    const double far = 150 * 8 / ((d - 0.01) * 0.0208);
    EXPECT_NEAR((far - 6000) / 0.01, depthResolutionMm(150, 8, 6000, 20.8, 1.0), 1.0);
}

TEST(DesignFigures, MinimumRangeOfTheDisparitySearch) {
    // 64 disparities from 0: d_max = 63 px; R_min = 150 * 8 / (0.0208 * 63) = 915.75 mm.
    EXPECT_NEAR(minimumRangeMm(150, 8, 20.8, 0, 64), 1200.0 / (0.0208 * 63), 1e-9);
    EXPECT_NEAR(minimumRangeMm(150, 8, 20.8, 16, 64), 1200.0 / (0.0208 * 79), 1e-9);
    EXPECT_TRUE(std::isnan(minimumRangeMm(150, 8, 20.8, 0, 0)));
}

TEST(DesignFigures, FieldOfViewAndThePanel) {
    // 320 px of 20.8 um = 6.656 mm of sensor: 2 atan(6.656 / 16) = 45.18 deg with 8 mm.
    EXPECT_NEAR(fieldOfViewDeg(320, 20.8, 8), 2 * std::atan(6.656 / 16) * 180 / M_PI, 1e-9);
    EXPECT_NEAR(fieldOfViewDeg(320, 20.8, 8), 45.18, 0.01);
    EXPECT_NEAR(fieldWidthMm(6000, 320, 20.8, 8), 4992, 1e-9);

    StereoDesign d;
    d.baseline_mm = 150;
    d.focal_length_mm = 8;
    d.pixel_pitch_um = 20.8;
    d.image_width_px = 320;
    d.image_height_px = 240;
    d.num_disparities = 64;
    const PanelPlacement panel; // 2.5 m x 2.0 m, centred, on the ground
    const DesignFigures f = designFigures(d, 6000, 0.25, &panel);
    EXPECT_NEAR(f.form_factor, 2.0, 1e-12);
    EXPECT_NEAR(f.field_width_mm, 4992, 1e-9);
    // The matcher's 63 blind columns cover 63 * 15.6 mm = 982.8 mm at 6 m (more than B).
    EXPECT_NEAR(f.stereo_field_min_x_mm, -2496 + 982.8, 1e-6);
    EXPECT_NEAR(f.stereo_field_width_mm, 4992 - 982.8, 1e-6);
    // Vertical: 240 px -> half height 6000 * 2.496 / 8 = 1872 mm about hc = 1500.
    EXPECT_NEAR(f.field_bottom_z_mm, 1500 - 1872, 1e-6);
    EXPECT_NEAR(f.field_top_z_mm, 1500 + 1872, 1e-6);
    EXPECT_TRUE(f.panel_fits_width);
    EXPECT_TRUE(f.panel_fits_height);
    EXPECT_NEAR(f.panel_width_ratio, 2500 / (4992 - 982.8), 1e-9);

    // 12 mm at 6 m: the field's lower edge is 252 mm above the ground: the panel's bottom
    // row is cut (METHOD.md: 12 mm too narrow at 6 m).
    d.focal_length_mm = 12;
    const DesignFigures narrow = designFigures(d, 6000, 0.25, &panel);
    EXPECT_NEAR(narrow.field_bottom_z_mm, 1500 - 6000 * 2.496 / 12, 1e-6);
    EXPECT_FALSE(narrow.panel_fits_height);

    // Pitched down 10 deg: the field's lower edge moves down.
    d.focal_length_mm = 8;
    d.inclination_deg = 10;
    const DesignFigures pitched = designFigures(d, 6000, 0.25, &panel);
    const double half = std::atan(2.496 / 8);
    EXPECT_NEAR(pitched.field_bottom_z_mm, 1500 - 6000 * std::tan(10 * M_PI / 180 + half), 1e-6);
}

TEST(DesignFigures, RefusesNonPositiveInputs) {
    StereoDesign d;
    d.baseline_mm = 150;
    d.focal_length_mm = 0;
    d.pixel_pitch_um = 20.8;
    try {
        designFigures(d, 6000);
        FAIL() << "no exception";
    } catch (const std::invalid_argument &e) {
        EXPECT_NE(std::string(e.what()).find("focal_length_mm = 0"), std::string::npos) << e.what();
    }
    d.focal_length_mm = 8;
    const DesignFigures f = designFigures(d, 6000); // no image size: field figures missing
    EXPECT_TRUE(std::isnan(f.horizontal_fov_deg));
    EXPECT_TRUE(std::isnan(f.min_range_mm));
}

} // namespace
} // namespace binocle::method
