// SPDX-License-Identifier: MIT
// bm plugin (cv::StereoBM): its own settings.
#include "plugin_fixtures.hpp"

#include <gtest/gtest.h>

namespace binocle::test {
namespace {

// cv::StereoBM refuses a window as large as the image's smaller side; the plugin says so first.
TEST(BmPlugin, RefusesABlockLargerThanTheImage) {
    const StereoPair pair = shiftedPair({80, 24}, 4);
    Matcher m = makeMatcher("bm", "{num_disparities: 16, block_size: 25}");
    const std::string e = errorOf([&] { m.compute(pair.left, pair.right); });
    EXPECT_NE(e.find("block_size = 25: expected less than 24"), std::string::npos) << e;
}

TEST(BmPlugin, PreFilterTypeIsAChoice) {
    const std::string e = errorOf([] { makeMatcher("bm", "{pre_filter_type: sobel}"); });
    EXPECT_NE(e.find("pre_filter_type"), std::string::npos) << e;
    EXPECT_NE(e.find("xsobel"), std::string::npos) << e;

    const StereoPair pair = shiftedPair({200, 120}, 10);
    Matcher m = makeMatcher("bm", "{num_disparities: 32, block_size: 9, pre_filter_type: normalized_response, "
                                  "pre_filter_size: 7, texture_threshold: 0}");
    const cv::Mat d = m.compute(pair.left, pair.right);
    const DisparityScore s = scoreDisparity(d, cv::Mat(d.size(), CV_32F, cv::Scalar(10)), 1.0,
                                            cv::Rect(45, 10, 145, 100));
    EXPECT_GT(s.density * (1 - s.bad), 0.9);
}

} // namespace
} // namespace binocle::test
