// SPDX-License-Identifier: MIT
// What bm and sgbm share (plugins/common/opencv_matcher.hpp), run on both through the
// host, and their figures on a real rectified pair.
#include "plugin_fixtures.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <iostream>
#include <opencv2/imgproc.hpp>

namespace binocle::test {
namespace {

class OpenCvMatcherTest : public ::testing::TestWithParam<std::string> {};

// A random texture shifted by 20 px: in the part of the image where the whole window
// and search range fit, at least 95 % of the pixels must hold 20 +- 1 px.
TEST_P(OpenCvMatcherTest, RecoversTheShiftOfASyntheticPair) {
    const int shift = 20, numDisparities = 64, block = 9;
    const StereoPair pair = shiftedPair({320, 240}, shift);
    Matcher m = makeMatcher(GetParam(), "{num_disparities: 64, block_size: 9}");
    const cv::Mat d = m.compute(pair.left, pair.right);

    const cv::Rect matchable(numDisparities + block, block, 320 - numDisparities - 2 * block, 240 - 2 * block);
    const DisparityScore s = scoreDisparity(d, cv::Mat(d.size(), CV_32F, cv::Scalar(shift)), 1.0, matchable);
    const double recovered = s.density * (1 - s.bad);
    std::cout << GetParam() << " synthetic shift 20 px: density " << s.density << ", |d - 20| > 1 px on " << s.bad
              << ", recovered " << recovered << ", mean error " << s.meanError << " px\n";
    RecordProperty("recovered", std::to_string(recovered));
    EXPECT_GE(recovered, 0.95);
    EXPECT_LT(std::abs(s.meanError), 0.25);
}

// BGR8 (what the host sends for CV_8UC3), RGB8 and GRAY8 of the same scene give the
// same map: the colour is only ever turned to grey, with the right channel order.
TEST_P(OpenCvMatcherTest, BgrRgbAndGreyInputsGiveTheSameMap) {
    const StereoPair grey = shiftedPair({200, 120}, 12);
    StereoPair bgr;
    // Distinct channels, so that a swapped channel order would change the grey image.
    cv::Mat zero = cv::Mat::zeros(grey.left.size(), CV_8UC1);
    cv::merge(std::vector<cv::Mat>{grey.left / 8, grey.left, zero}, bgr.left);
    cv::merge(std::vector<cv::Mat>{grey.right / 8, grey.right, zero}, bgr.right);
    StereoPair rgb, grey2;
    cv::cvtColor(bgr.left, rgb.left, cv::COLOR_BGR2RGB);
    cv::cvtColor(bgr.right, rgb.right, cv::COLOR_BGR2RGB);
    cv::cvtColor(bgr.left, grey2.left, cv::COLOR_BGR2GRAY);
    cv::cvtColor(bgr.right, grey2.right, cv::COLOR_BGR2GRAY);

    const std::string yaml = "{num_disparities: 32, block_size: 7}";
    Matcher m = makeMatcher(GetParam(), yaml);
    const cv::Mat fromBgr = m.compute(bgr.left, bgr.right).clone();
    const cv::Mat fromGrey = m.compute(grey2.left, grey2.right).clone();

    RawMatcher raw(GetParam(), yaml);
    cv::Mat fromRgb(fromBgr.size(), CV_32F, cv::Scalar(0));
    binocle_image d = imageOf(fromRgb, BINOCLE_PIXEL_FLOAT32);
    ASSERT_EQ(raw.compute(imageOf(rgb.left, BINOCLE_PIXEL_RGB8), imageOf(rgb.right, BINOCLE_PIXEL_RGB8), d), BINOCLE_OK)
        << raw.lastError();

    EXPECT_EQ(cv::countNonZero(fromBgr != fromGrey), 0);
    EXPECT_EQ(cv::countNonZero(fromBgr != fromRgb), 0);
    EXPECT_GT(cv::countNonZero(fromBgr > 0), fromBgr.total() / 2);
}

// Views into larger images (stride > width) are read row by row as the stride says.
TEST_P(OpenCvMatcherTest, ReadsStridedViews) {
    const StereoPair big = shiftedPair({300, 200}, 16);
    const cv::Rect roi(40, 30, 200, 120);
    const cv::Mat leftView = big.left(roi), rightView = big.right(roi);
    ASSERT_FALSE(leftView.isContinuous());

    Matcher m = makeMatcher(GetParam(), "{num_disparities: 32, block_size: 7}");
    const cv::Mat fromView = m.compute(leftView, rightView).clone();
    const cv::Mat fromCopy = m.compute(leftView.clone(), rightView.clone());
    EXPECT_EQ(cv::countNonZero(fromView != fromCopy), 0);
}

// Disparities lie in the search window or are exactly BINOCLE_INVALID_DISPARITY; the
// left margin, where no match is possible, is invalid.
TEST_P(OpenCvMatcherTest, WritesTheWindowOrInvalid) {
    const StereoPair pair = shiftedPair({240, 160}, 30);
    Matcher m = makeMatcher(GetParam(), "{min_disparity: 16, num_disparities: 32, block_size: 7}");
    EXPECT_EQ(m.disparityRange(), std::make_pair(16, 32));
    const cv::Mat d = m.compute(pair.left, pair.right);
    int valid = 0, outside = 0;
    for (int v = 0; v < d.rows; ++v)
        for (int u = 0; u < d.cols; ++u) {
            const float x = d.at<float>(v, u);
            if (x == BINOCLE_INVALID_DISPARITY) continue;
            ++valid;
            if (x < 16 || x > 16 + 32 - 1 || u < 16) ++outside;
        }
    EXPECT_GT(valid, 0);
    EXPECT_EQ(outside, 0);
}

// The keys of a typical rig are accepted by both: swapping `plugin:` is the only edit.
TEST_P(OpenCvMatcherTest, AcceptsATypicalRigBlock) {
    const std::string typical = "{min_disparity: 0, num_disparities: 128, block_size: 5, pre_filter_cap: 31, "
                                "uniqueness_ratio: 10, speckle_window_size: 100, speckle_range: 2, disp12_max_diff: 1}";
    Matcher m = makeMatcher(GetParam(), typical);
    EXPECT_EQ(m.disparityRange(), std::make_pair(0, 128));
}

TEST_P(OpenCvMatcherTest, RefusesNumDisparitiesNotAMultipleOf16) {
    expectRefused<Matcher>(matcherRecord(GetParam()), "num_disparities", "100", "multiple of 16",
                           "num_disparities = 100: expected an integer multiple of 16 >= 16");
}

TEST_P(OpenCvMatcherTest, RefusesAnEvenBlockSize) {
    expectRefused<Matcher>(matcherRecord(GetParam()), "block_size", "8", "odd", "block_size = 8: expected an odd integer");
}

TEST_P(OpenCvMatcherTest, RefusesASearchWiderThanTheImage) {
    const StereoPair pair = shiftedPair({64, 48}, 4);
    Matcher m = makeMatcher(GetParam(), "{num_disparities: 64, block_size: 5}");
    const std::string e = errorOf([&] { m.compute(pair.left, pair.right); });
    EXPECT_NE(e.find("min_disparity + num_disparities = 64: expected less than the image width 64"), std::string::npos)
        << e;
}

// What the host's wrapper would never send, sent to the C table directly.
TEST_P(OpenCvMatcherTest, RefusesBadImagesWithAClearMessage) {
    RawMatcher raw(GetParam(), "{num_disparities: 16, block_size: 5}");
    const StereoPair pair = shiftedPair({64, 48}, 4);
    cv::Mat rgbRight, out(48, 64, CV_32F), smallOut(40, 64, CV_32F), grey8(48, 64, CV_8U), wide(48, 70, CV_8U);
    cv::cvtColor(pair.right, rgbRight, cv::COLOR_GRAY2RGB);
    const binocle_image l = imageOf(pair.left, BINOCLE_PIXEL_GRAY8), r = imageOf(pair.right, BINOCLE_PIXEL_GRAY8);

    struct Case {
        binocle_image left, right, disparity;
        const char *expected;
    };
    binocle_image floatLeft = imageOf(out, BINOCLE_PIXEL_FLOAT32);
    binocle_image badStride = l;
    badStride.stride_bytes = 10;
    const Case cases[] = {
        {floatLeft, floatLeft, imageOf(out, BINOCLE_PIXEL_FLOAT32), "left image is FLOAT32: expected GRAY8, BGR8 or RGB8"},
        {l, imageOf(rgbRight, BINOCLE_PIXEL_RGB8), imageOf(out, BINOCLE_PIXEL_FLOAT32),
         "right image is RGB8: expected GRAY8, the format of the left image"},
        {l, imageOf(wide, BINOCLE_PIXEL_GRAY8), imageOf(out, BINOCLE_PIXEL_FLOAT32),
         "right image is 70x48: expected 64x48, the size of the left image"},
        {l, r, imageOf(grey8, BINOCLE_PIXEL_GRAY8), "disparity image is GRAY8: expected FLOAT32"},
        {l, r, imageOf(smallOut, BINOCLE_PIXEL_FLOAT32), "disparity image is 64x40: expected 64x48"},
        {badStride, badStride, imageOf(out, BINOCLE_PIXEL_FLOAT32), "left image stride is 10 bytes: expected at least 64"},
    };
    for (const Case &c : cases) {
        binocle_image d = c.disparity;
        EXPECT_EQ(raw.compute(c.left, c.right, d), BINOCLE_ERR_INVALID_ARGUMENT) << c.expected;
        EXPECT_NE(raw.lastError().find(c.expected), std::string::npos) << raw.lastError();
    }
}

INSTANTIATE_TEST_SUITE_P(BmAndSgbm, OpenCvMatcherTest, ::testing::Values("bm", "sgbm"),
                         [](const ::testing::TestParamInfo<std::string> &i) { return i.param; });

// OpenCV's aloe pair against its ground truth (disparities 43..211 px, hence 224), with
// each matcher's default block size. Measured with OpenCV 4.6, pixels off by more than
// 3 px / density over pixels with a known truth / mean error:
//   bm   1.5 % / 62.7 % / +0.6 px
//   sgbm 2.7 % / 72.3 % / +0.8 px
struct AloeCase {
    const char *plugin, *yaml;
    double maxBad, minDensity;
};

class AloeTest : public ::testing::TestWithParam<AloeCase> {};

TEST_P(AloeTest, AgreesWithTheGroundTruth) {
    const DisparityScore s = aloeScore(GetParam().plugin, GetParam().yaml);
    EXPECT_LT(s.bad, GetParam().maxBad);
    EXPECT_GT(s.density, GetParam().minDensity);
    EXPECT_LT(std::abs(s.meanError), 1.5);
}

INSTANTIATE_TEST_SUITE_P(BmAndSgbm, AloeTest,
                         ::testing::Values(AloeCase{"bm", "{num_disparities: 224, block_size: 15}", 0.03, 0.55},
                                           AloeCase{"sgbm", "{num_disparities: 224, block_size: 5}", 0.04, 0.65}),
                         [](const ::testing::TestParamInfo<AloeCase> &i) { return std::string(i.param.plugin); });

// The shared keys are declared alike (type, default, range, unit) by both plugins.
TEST(OpenCvMatchers, DeclareTheSharedKeysAlike) {
    const std::vector<binocle_param_desc> bm = matcherRecord("bm").params(), sgbm = matcherRecord("sgbm").params();
    int shared = 0;
    for (const binocle_param_desc &a : bm)
        for (const binocle_param_desc &b : sgbm) {
            if (std::strcmp(a.name, b.name) != 0 || std::strcmp(a.name, "block_size") == 0) continue;
            ++shared;
            EXPECT_EQ(a.type, b.type) << a.name;
            EXPECT_EQ(a.flags, b.flags) << a.name;
            EXPECT_STREQ(a.default_value, b.default_value) << a.name;
            EXPECT_EQ(a.min, b.min) << a.name;
            EXPECT_EQ(a.max, b.max) << a.name;
            EXPECT_EQ(a.multiple_of, b.multiple_of) << a.name;
            EXPECT_STREQ(a.unit, b.unit) << a.name;
        }
    EXPECT_EQ(shared, 7);
}

} // namespace
} // namespace binocle::test
