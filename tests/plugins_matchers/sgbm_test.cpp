// SPDX-License-Identifier: MIT
// sgbm plugin (cv::StereoSGBM): penalties, block size cap and modes.
#include "plugin_fixtures.hpp"

#include <gtest/gtest.h>

namespace binocle::test {
namespace {

// Unset p1 and p2 are OpenCV's rule of thumb for one channel: 8 and 32 * block_size^2.
TEST(SgbmPlugin, DerivesPenaltiesFromTheBlockSize) {
    const StereoPair pair = shiftedPair({200, 120}, 10);
    cv::Mat derived = makeMatcher("sgbm", "{num_disparities: 32, block_size: 5}").compute(pair.left, pair.right);
    cv::Mat same = makeMatcher("sgbm", "{num_disparities: 32, block_size: 5, p1: 200, p2: 800}").compute(pair.left, pair.right);
    cv::Mat other = makeMatcher("sgbm", "{num_disparities: 32, block_size: 5, p1: 10, p2: 20}").compute(pair.left, pair.right);
    EXPECT_EQ(cv::countNonZero(derived != same), 0);
    EXPECT_GT(cv::countNonZero(derived != other), 0);
}

TEST(SgbmPlugin, RefusesP2NotAboveP1) {
    const std::string set = errorOf([] { makeMatcher("sgbm", "{p1: 500, p2: 400}"); });
    EXPECT_NE(set.find("p2 = 400 (set): expected more than p1 = 500 (set)"), std::string::npos) << set;
    const std::string derived = errorOf([] { makeMatcher("sgbm", "{block_size: 5, p1: 1000}"); });
    EXPECT_NE(derived.find("p2 = 800 (derived: 32 * block_size^2): expected more than p1 = 1000 (set)"),
              std::string::npos)
        << derived;
}

// Beyond 21 the derived penalties overflow OpenCV's 16-bit costs (see README.md).
TEST(SgbmPlugin, RefusesABlockOverTheCap) {
    const std::string e = errorOf([] { makeMatcher("sgbm", "{block_size: 23}"); });
    EXPECT_NE(e.find("block_size"), std::string::npos) << e;
    EXPECT_NE(e.find("21"), std::string::npos) << e;
}

class SgbmModeTest : public ::testing::TestWithParam<std::string> {};

TEST_P(SgbmModeTest, RecoversTheShiftOfASyntheticPair) {
    const StereoPair pair = shiftedPair({240, 160}, 20);
    Matcher m = makeMatcher("sgbm", "{num_disparities: 48, block_size: 5, mode: " + GetParam() + "}");
    const cv::Mat d = m.compute(pair.left, pair.right);
    const DisparityScore s = scoreDisparity(d, cv::Mat(d.size(), CV_32F, cv::Scalar(20)), 1.0,
                                            cv::Rect(58, 10, 240 - 68, 140));
    EXPECT_GE(s.density * (1 - s.bad), 0.95) << "density " << s.density << ", bad " << s.bad;
}

INSTANTIATE_TEST_SUITE_P(Modes, SgbmModeTest, ::testing::Values("sgbm", "hh", "sgbm_3way", "hh4"),
                         [](const ::testing::TestParamInfo<std::string> &i) { return i.param; });

} // namespace
} // namespace binocle::test
