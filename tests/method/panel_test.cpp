// SPDX-License-Identifier: MIT
// Reading X', Y', Z' of the E1 panel from synthetic clouds with known distortions, and
// the relative errors (Eq. 2-4) and efficiencies (Eq. 5-6) that follow.
#include "method/panel.hpp"
#include "synthetic_cloud.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace binocle::test {
namespace {

using namespace binocle::method;

const PanelSize kTruth{2500, 6000, 2000};

PanelReadingOptions options(double expectedRange = 6000) {
    PanelReadingOptions o;
    o.expected_range_mm = expectedRange;
    return o;
}

std::string describe(const PanelReading &r) {
    return "X' " + std::to_string(r.width_mm) + " Y' " + std::to_string(r.range_mm) + " Z' " +
           std::to_string(r.height_mm) + " points " + std::to_string(r.points) + " " + r.reason;
}

TEST(PanelReading, ExactPanelGivesNoError) {
    const std::vector<float> xyz = panelScene();
    const PanelReading r = readPanel(CloudView(xyz), options());
    ASSERT_TRUE(r.registered) << r.reason;
    EXPECT_NEAR(r.x_min_mm, -1250, 6) << describe(r);
    EXPECT_NEAR(r.x_max_mm, 1250, 6) << describe(r);
    EXPECT_NEAR(r.z_top_mm, 2000, 6) << describe(r);
    EXPECT_NEAR(r.ground_z_mm, 0, 3) << describe(r);
    EXPECT_TRUE(r.stands_on_ground);
    const PanelScore s = scorePanel(r.size(), kTruth, r.registered);
    EXPECT_LT(s.epsilon_x_percent, 0.3) << describe(r);
    EXPECT_LT(s.epsilon_y_percent, 0.1) << describe(r);
    EXPECT_LT(s.epsilon_z_percent, 0.3) << describe(r);
    EXPECT_GT(s.eta_2d_percent, 99.7);
    EXPECT_GT(s.eta_3d_percent, 99.7);
}

TEST(PanelReading, StretchedFivePercentInWidth) {
    std::vector<float> xyz = panelScene();
    stretchX(xyz, 1.05);
    const PanelReading r = readPanel(CloudView(xyz), options());
    ASSERT_TRUE(r.registered) << r.reason;
    const PanelScore s = scorePanel(r.size(), kTruth, r.registered);
    EXPECT_NEAR(s.epsilon_x_percent, 5.0, 0.5) << describe(r);
    EXPECT_LT(s.epsilon_y_percent, 0.1) << describe(r);
    EXPECT_LT(s.epsilon_z_percent, 0.3) << describe(r);
    EXPECT_NEAR(s.eta_2d_percent, 100 - (s.epsilon_x_percent + s.epsilon_z_percent) / 2, 1e-9);
}

TEST(PanelReading, ShiftedThreePercentInRange) {
    std::vector<float> xyz = panelScene();
    shiftY(xyz, 0.03 * 6000);
    const PanelReading r = readPanel(CloudView(xyz), options());
    ASSERT_TRUE(r.registered) << r.reason;
    const PanelScore s = scorePanel(r.size(), kTruth, r.registered);
    EXPECT_NEAR(s.epsilon_y_percent, 3.0, 0.1) << describe(r);
    EXPECT_LT(s.epsilon_x_percent, 0.3) << describe(r);
    EXPECT_NEAR(s.eta_3d_percent, 100 - (s.epsilon_x_percent + s.epsilon_y_percent + s.epsilon_z_percent) / 3, 1e-9);
}

TEST(PanelReading, NoisyRangeAndACoarseSampling) {
    SyntheticScene scene;
    scene.range_mm = 12000;
    scene.step_mm = 40;          // a far panel: fewer points
    scene.range_noise_mm = 120;  // 1 % range noise
    scene.outliers = 200;
    const std::vector<float> xyz = panelScene(scene);
    const PanelReading r = readPanel(CloudView(xyz), options(12000));
    ASSERT_TRUE(r.registered) << r.reason;
    const PanelScore s = scorePanel(r.size(), {2500, 12000, 2000}, r.registered);
    EXPECT_LT(s.epsilon_x_percent, 1.0) << describe(r);
    EXPECT_LT(s.epsilon_y_percent, 0.2) << describe(r);
    EXPECT_LT(s.epsilon_z_percent, 1.0) << describe(r);
}

// The band is found near the true range even when the cloud puts the panel 20 % off.
TEST(PanelReading, FindsThePanelAwayFromTheExpectedRange) {
    std::vector<float> xyz = panelScene();
    shiftY(xyz, 1200);
    const PanelReading r = readPanel(CloudView(xyz), options());
    ASSERT_TRUE(r.registered) << r.reason;
    EXPECT_NEAR(r.range_mm, 7200, 5);
    EXPECT_NEAR(r.width_mm, 2500, 15);
}

TEST(PanelReading, NoPanelIsARejectedConfiguration) {
    SyntheticScene scene;
    scene.panel = false;
    const std::vector<float> xyz = panelScene(scene);
    const PanelReading r = readPanel(CloudView(xyz), options());
    EXPECT_FALSE(r.registered);
    EXPECT_NE(r.reason.find("no panel"), std::string::npos) << r.reason;
    EXPECT_TRUE(std::isnan(r.width_mm));
    const PanelScore s = scorePanel(r.size(), kTruth, r.registered);
    EXPECT_TRUE(std::isnan(s.epsilon_x_percent));
    EXPECT_TRUE(std::isnan(s.epsilon_y_percent));
    EXPECT_TRUE(std::isnan(s.epsilon_z_percent));
    EXPECT_EQ(s.eta_2d_percent, 0);
    EXPECT_EQ(s.eta_3d_percent, 0);

    // An empty cloud too.
    const PanelReading none = readPanel(CloudView(), options());
    EXPECT_FALSE(none.registered);
}

TEST(PanelReading, AFloatingPanelIsMeasuredFromItsLowerEdge) {
    CloudBuilder b(5);
    b.frontFace(-1250, 1250, 800, 2800, 6000, 10, 4);
    b.ground(-5000, 5000, 1000, 20000, 100, 4);
    const PanelReading r = readPanel(CloudView(b.xyz), options());
    ASSERT_TRUE(r.registered) << r.reason;
    EXPECT_FALSE(r.stands_on_ground);
    EXPECT_NEAR(r.z_bottom_mm, 800, 6);
    EXPECT_NEAR(r.height_mm, 2000, 12);
}

// ---- Hard cases of the region reading (README: "Reading X', Y', Z' of the E1 panel") ----

// The E1 panel (10 mm spacing, 5 mm noise) on a ground, plus whatever `more` adds.
template <typename More>
std::vector<float> panelWith(More more, double range = 6000) {
    SyntheticScene scene;
    scene.range_mm = range;
    CloudBuilder b(11);
    const std::vector<float> base = panelScene(scene);
    b.xyz = base;
    more(b);
    return b.xyz;
}

// A wall beside the panel at the same range, touching its right edge, a quarter as dense
// (a plainer surface the matcher matched less): split at the density edge.
TEST(PanelRegion, SplitsAWallBesideThePanelAtItsDensityEdge) {
    const auto xyz = panelWith([](CloudBuilder &b) { b.frontFace(1250, 5000, 0, 3000, 6050, 20, 5); });
    const PanelReading r = readPanel(CloudView(xyz), options());
    ASSERT_TRUE(r.registered) << r.reason;
    EXPECT_NEAR(r.x_min_mm, -1250, 30) << describe(r);
    EXPECT_NEAR(r.x_max_mm, 1250, 60) << describe(r);
    // The reading before issue 33 took the wall with it.
    PanelReadingOptions band = options();
    band.method = PanelReadingMethod::Band;
    EXPECT_GT(readPanel(CloudView(xyz), band).width_mm, 5500);
}

// Ground points lifted into the band (a depth error of the ground at range) along the
// whole field, as dense as the panel in their rows: the panel's edges are where most of
// its rows end, so the strip along the bottom does not widen it.
TEST(PanelRegion, GroundClutterAlongTheBottomDoesNotWidenIt) {
    const auto xyz = panelWith([](CloudBuilder &b) {
        for (double y = 5700; y <= 6300; y += 150) b.topFace(-5000, 5000, y, y + 10, 250, 10, 40);
    });
    const PanelReading r = readPanel(CloudView(xyz), options());
    ASSERT_TRUE(r.registered) << r.reason;
    EXPECT_NEAR(r.width_mm, 2500, 150) << describe(r);
    EXPECT_TRUE(r.stands_on_ground);
}

// A matcher's smear beside the top cubes: points spread in range between the panel and
// the background (a depth step in the top view), as dense as the panel in the front view
// of the whole cloud. The band narrowed to the panel's own depth keeps most of it out,
// and the rest is under the panel's density.
TEST(PanelRegion, SmearedFillBesideThePanelIsLeftOut) {
    const auto xyz = panelWith([](CloudBuilder &b) {
        std::uniform_real_distribution<double> x(1250, 2200), z(1400, 2100), y(4200, 6400);
        for (int i = 0; i < 6000; ++i) b.point(x(b.rng()), y(b.rng()), z(b.rng()));
    });
    const PanelReading r = readPanel(CloudView(xyz), options());
    ASSERT_TRUE(r.registered) << r.reason;
    EXPECT_NEAR(r.x_max_mm, 1250, 80) << describe(r);
    EXPECT_NEAR(r.width_mm, 2500, 120) << describe(r);
}

// The panel partly out of the stereo field: the reading takes what the cloud shows
// (the paper evaluator reports panel_fits beside it).
TEST(PanelRegion, APanelCutByTheFieldIsReadAsFarAsItIsSeen) {
    std::vector<float> xyz;
    const std::vector<float> all = panelScene();
    for (size_t i = 0; i < all.size(); i += 3)
        if (all[i] < 1100) xyz.insert(xyz.end(), {all[i], all[i + 1], all[i + 2]});
    const PanelReading r = readPanel(CloudView(xyz), options());
    ASSERT_TRUE(r.registered) << r.reason;
    EXPECT_NEAR(r.x_min_mm, -1250, 30) << describe(r);
    EXPECT_NEAR(r.x_max_mm, 1100, 60) << describe(r);
}

// The middle column not matched (OpenCV's bm on the chessboard at 12 m): the outer
// columns are within a metre of the stated position and give the width.
TEST(PanelRegion, AMissingMiddleColumnStillGivesTheOuterEdges) {
    std::vector<float> xyz;
    const std::vector<float> all = panelScene();
    for (size_t i = 0; i < all.size(); i += 3)
        if (std::abs(all[i]) > 300 || all[i + 2] < 150) xyz.insert(xyz.end(), {all[i], all[i + 1], all[i + 2]});
    const PanelReading r = readPanel(CloudView(xyz), options());
    ASSERT_TRUE(r.registered) << r.reason;
    EXPECT_NEAR(r.width_mm, 2500, 30) << describe(r);
}

// Clutter as dense as the panel, at its range and touching it over its whole height (a
// wall flush with its face): nothing tells them apart, and the reading says so instead
// of reading a 5 m panel.
TEST(PanelRegion, AWallFlushWithThePanelIsNotSeparated) {
    const auto xyz = panelWith([](CloudBuilder &b) { b.frontFace(1250, 5000, 0, 2000, 6000, 10, 5); });
    PanelReadingOptions o = options();
    o.expected_width_mm = 2500;
    const PanelReading r = readPanel(CloudView(xyz), o);
    EXPECT_FALSE(r.registered) << describe(r);
    EXPECT_NE(r.reason.find("not separated"), std::string::npos) << r.reason;
    EXPECT_TRUE(std::isnan(r.width_mm));
    EXPECT_FALSE(r.front_cells.empty()); // what it took is still there to draw
}

// The stated lateral position is where the reading starts: a panel 3 m to the right
// is found when it is stated there, and not when it is stated in front of the rig.
TEST(PanelRegion, StartsAtTheStatedLateralPosition) {
    std::vector<float> xyz = panelScene();
    for (size_t i = 0; i < xyz.size(); i += 3)
        if (xyz[i + 2] > 150) xyz[i] += 3000; // the panel, not the ground
    PanelReadingOptions o = options();
    o.expected_x_mm = 3000;
    const PanelReading r = readPanel(CloudView(xyz), o);
    ASSERT_TRUE(r.registered) << r.reason;
    EXPECT_NEAR((r.x_min_mm + r.x_max_mm) / 2, 3000, 30) << describe(r);
    EXPECT_FALSE(readPanel(CloudView(xyz), options()).registered);
}

TEST(PanelReading, RefusesBadOptions) {
    PanelReadingOptions o = options();
    o.range_margin_mm = 0;
    EXPECT_THROW(readPanel(CloudView(), o), std::invalid_argument);
    o = options();
    o.grid.cell_mm = -1;
    EXPECT_THROW(readPanel(CloudView(), o), std::invalid_argument);
    o = options();
    o.relative_density = 1.5;
    EXPECT_THROW(readPanel(CloudView(), o), std::invalid_argument);
    o = options();
    o.seed_half_width_mm = 0;
    EXPECT_THROW(readPanel(CloudView(), o), std::invalid_argument);
}

} // namespace
} // namespace binocle::test
