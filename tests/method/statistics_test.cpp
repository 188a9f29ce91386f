// SPDX-License-Identifier: MIT
// Statistics of repeats and predictors against values from tables and by hand.
#include "method/statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace binocle::method;

TEST(Statistics, StudentTMatchesTheTable) {
    // Two-sided 95 % critical values of any statistics textbook.
    EXPECT_NEAR(studentT(0.95, 1), 12.7062, 1e-3);
    EXPECT_NEAR(studentT(0.95, 2), 4.3027, 1e-4);
    EXPECT_NEAR(studentT(0.95, 9), 2.2622, 1e-4);
    EXPECT_NEAR(studentT(0.95, 29), 2.0452, 1e-4);
    EXPECT_NEAR(studentT(0.95, 100000), 1.95997, 1e-4);
    EXPECT_NEAR(studentT(0.99, 4), 4.6041, 1e-4);
    EXPECT_THROW(studentT(0.95, 0), std::invalid_argument);
    EXPECT_THROW(studentT(1.0, 5), std::invalid_argument);
}

TEST(Statistics, SummaryOfTenRepeats) {
    const Summary s = summarize({92, 94, 91, 95, 93, 90, 96, 94, 92, 93});
    EXPECT_EQ(s.n, 10);
    EXPECT_DOUBLE_EQ(s.mean, 93.0);
    // sum of squared deviations 30 -> sd sqrt(30 / 9)
    EXPECT_NEAR(s.sd, std::sqrt(30.0 / 9), 1e-12);
    const double half = 2.262157 * std::sqrt(30.0 / 9) / std::sqrt(10.0);
    EXPECT_NEAR(s.ci95_low, 93 - half, 1e-5);
    EXPECT_NEAR(s.ci95_high, 93 + half, 1e-5);
    EXPECT_NEAR(s.halfWidth(), half, 1e-5);
}

TEST(Statistics, SummaryLeavesOutMissingSamplesAndSaysWhenNoIntervalExists) {
    const Summary s = summarize({80, NAN, 90});
    EXPECT_EQ(s.n, 2);
    EXPECT_DOUBLE_EQ(s.mean, 85);
    EXPECT_TRUE(std::isfinite(s.ci95_low));
    const Summary one = summarize({80});
    EXPECT_EQ(one.n, 1);
    EXPECT_DOUBLE_EQ(one.mean, 80);
    EXPECT_DOUBLE_EQ(one.sd, 0);
    EXPECT_TRUE(std::isnan(one.ci95_low));
    EXPECT_TRUE(std::isnan(summarize({}).mean));
}

TEST(Statistics, RanksAverageTies) {
    const auto r = ranks({10, 30, 20, 30, 5});
    const std::vector<double> want{2, 4.5, 3, 4.5, 1};
    EXPECT_EQ(r, want);
}

TEST(Statistics, SpearmanMonotoneInverseTiedAndMissing) {
    EXPECT_DOUBLE_EQ(spearman({1, 2, 3, 4, 5}, {1, 4, 9, 16, 100}), 1.0);
    EXPECT_DOUBLE_EQ(spearman({1, 2, 3, 4, 5}, {5, 4, 3, 2, 1}), -1.0);
    // Hand computation: ranks x 1 2 3 4 5, y 2 1 4 3 5 -> sum d^2 = 4, rho = 1 - 6*4/(5*24) = 0.8
    EXPECT_NEAR(spearman({1, 2, 3, 4, 5}, {20, 10, 40, 30, 50}), 0.8, 1e-12);
    // A missing value drops its pair.
    EXPECT_NEAR(spearman({1, 2, 3, 4, 5, 6}, {20, 10, 40, 30, 50, NAN}), 0.8, 1e-12);
    // Ties: Pearson on averaged ranks. x ranks 1.5 1.5 3 4, y 1 2 3 4.
    const double rho = spearman({1, 1, 2, 3}, {1, 2, 3, 4});
    EXPECT_NEAR(rho, 4.5 / std::sqrt(4.5 * 5.0), 1e-12);
    EXPECT_TRUE(std::isnan(spearman({1, 2}, {1, 2})));
    EXPECT_TRUE(std::isnan(spearman({1, 1, 1}, {1, 2, 3})));
    EXPECT_THROW(spearman({1, 2, 3}, {1, 2}), std::invalid_argument);
}
