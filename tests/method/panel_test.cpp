// SPDX-License-Identifier: MIT
// Reading X', Y', Z' of the E1 panel from synthetic clouds with known distortions, and
// the relative errors (Eq. 2-4) and efficiencies (Eq. 5-6) that follow.
#include "method/panel.hpp"
#include "synthetic_cloud.hpp"

#include <gtest/gtest.h>

#include <cmath>

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

TEST(PanelReading, RefusesBadOptions) {
    PanelReadingOptions o = options();
    o.range_margin_mm = 0;
    EXPECT_THROW(readPanel(CloudView(), o), std::invalid_argument);
    o = options();
    o.grid.cell_mm = -1;
    EXPECT_THROW(readPanel(CloudView(), o), std::invalid_argument);
}

} // namespace
} // namespace binocle::test
