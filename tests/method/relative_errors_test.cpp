// SPDX-License-Identifier: MIT
// Relative errors (Eq. 2-4) and planar / stereo efficiencies (Eq. 5-6).
#include "method/relative_errors.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace binocle::method {
namespace {

TEST(RelativeErrors, Eq2To4ArePercentAndNeverNegative) {
    EXPECT_DOUBLE_EQ(relativeErrorPercent(2625, 2500), 5.0);
    EXPECT_DOUBLE_EQ(relativeErrorPercent(2375, 2500), 5.0);
    EXPECT_DOUBLE_EQ(relativeErrorPercent(6180, 6000), 3.0);
    EXPECT_DOUBLE_EQ(relativeErrorPercent(2000, 2000), 0.0);
    EXPECT_TRUE(std::isnan(relativeErrorPercent(NAN, 2500)));
    EXPECT_TRUE(std::isnan(relativeErrorPercent(2500, 0)));
}

TEST(Efficiencies, Eq5And6AreMeanErrorFormsClamped) {
    EXPECT_DOUBLE_EQ(planarEfficiencyPercent(4, 2), 97.0);        // 100 - (4 + 2) / 2
    EXPECT_DOUBLE_EQ(stereoEfficiencyPercent(4, 3, 2), 97.0);     // 100 - (4 + 3 + 2) / 3
    EXPECT_DOUBLE_EQ(stereoEfficiencyPercent(30, 15, 9), 82.0);   // the paper's 6 m best, for scale
    EXPECT_DOUBLE_EQ(planarEfficiencyPercent(250, 10), 0.0);      // clamped
    EXPECT_DOUBLE_EQ(stereoEfficiencyPercent(0, 0, 0), 100.0);
    EXPECT_DOUBLE_EQ(planarEfficiencyPercent(NAN, 1), 0.0);       // missing error: nothing delivered
}

TEST(PanelScore, RejectedConfigurationHasMissingErrorsAndZeroEfficiencies) {
    const PanelSize truth{2500, 6000, 2000};
    const PanelScore good = scorePanel({2625, 6180, 2000}, truth, true);
    EXPECT_DOUBLE_EQ(good.epsilon_x_percent, 5);
    EXPECT_DOUBLE_EQ(good.epsilon_y_percent, 3);
    EXPECT_DOUBLE_EQ(good.epsilon_z_percent, 0);
    EXPECT_DOUBLE_EQ(good.eta_2d_percent, 97.5);
    EXPECT_NEAR(good.eta_3d_percent, 100 - 8.0 / 3, 1e-12);

    const PanelScore rejected = scorePanel({2625, 6180, 2000}, truth, false);
    EXPECT_FALSE(rejected.registered);
    EXPECT_TRUE(std::isnan(rejected.epsilon_x_percent));
    EXPECT_TRUE(std::isnan(rejected.epsilon_y_percent));
    EXPECT_TRUE(std::isnan(rejected.epsilon_z_percent));
    EXPECT_EQ(rejected.eta_2d_percent, 0);
    EXPECT_EQ(rejected.eta_3d_percent, 0);
}

} // namespace
} // namespace binocle::method
