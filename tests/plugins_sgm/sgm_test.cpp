// SPDX-License-Identifier: MIT
// sgm plugin, as built, through the plugin host: accuracy on a synthetic pair and on the
// real aloe pair, settings refused with their reason, the ABI's invalid pixels, and the
// same disparity whatever the instruction set.
#include "../common/test_util.hpp"
#include "plugin_fixtures.hpp"

#include <gtest/gtest.h>

namespace binocle::test {
namespace {

class SgmPathsTest : public ::testing::TestWithParam<std::string> {};

TEST_P(SgmPathsTest, RecoversTheShiftOfASyntheticPair) {
    const StereoPair pair = shiftedPair({240, 160}, 20);
    Matcher m = makeMatcher("sgm", "{num_disparities: 48, paths: " + GetParam() + "}");
    const cv::Mat d = m.compute(pair.left, pair.right);
    const DisparityScore s = scoreDisparity(d, cv::Mat(d.size(), CV_32F, cv::Scalar(20)), 1.0, cv::Rect(58, 10, 240 - 68, 140));
    EXPECT_GE(s.density * (1 - s.bad), 0.97) << "density " << s.density << ", bad " << s.bad;
    EXPECT_LT(std::abs(s.meanError), 0.1);
}

INSTANTIATE_TEST_SUITE_P(Paths, SgmPathsTest, ::testing::Values("4", "5", "8"),
                         [](const ::testing::TestParamInfo<std::string> &i) { return "paths" + i.param; });

// The bar on the full-size aloe pair (256 disparities, as configs/rigs/opencv-aloe-sgm.yaml):
// bad-2 <= 3.5 % at density >= 85 %, and <= 20 % counting holes as errors.
TEST(SgmPlugin, MeetsTheAloeBarWithItsDefaults) {
    const AloePair a = loadAloe();
    Matcher m = makeMatcher("sgm", "{num_disparities: 256}");
    const cv::Mat d = m.compute(a.left, a.right);
    const DisparityScore s = scoreDisparity(d, a.gt, 2.0, cv::Rect(0, 0, d.cols, d.rows));
    const double holesAsErrors = s.density * s.bad + (1 - s.density);
    std::cout << "sgm on aloe: bad 2 px " << 100 * s.bad << " %, density " << 100 * s.density
              << " %, bad 2 px counting holes " << 100 * holesAsErrors << " %\n";
    EXPECT_LE(s.bad, 0.035);
    EXPECT_GE(s.density, 0.85);
    EXPECT_LE(holesAsErrors, 0.20);
}

// Every instruction set gives the very same disparity through the ABI.
TEST(SgmPlugin, KernelsAgreeThroughThePlugin) {
    const StereoPair pair = shiftedPair({203, 101}, 13, 7);
    const cv::Mat reference = makeMatcher("sgm", "{num_disparities: 32, kernels: scalar}").compute(pair.left, pair.right);
    for (const char *k : {"auto", "baseline"}) {
        const cv::Mat d = makeMatcher("sgm", std::string("{num_disparities: 32, kernels: ") + k + "}").compute(pair.left, pair.right);
        EXPECT_EQ(cv::countNonZero(d != reference), 0) << k;
    }
}

// fill: dense leaves no pixel invalid and marks the filled ones in the extra plane
// "disparity_filled", which evaluators receive (matcher.h: extras): exactly the pixels
// sgm without it leaves invalid; the matched ones keep their values. Without it, no plane.
TEST(SgmPlugin, DenseFillsTheHolesAndMarksThem) {
    const AloePair a = loadAloe();
    cv::Mat left, right;
    cv::resize(a.left, left, cv::Size(320, 277), 0, 0, cv::INTER_AREA);
    cv::resize(a.right, right, left.size(), 0, 0, cv::INTER_AREA);
    Matcher sparse = makeMatcher("sgm", "{num_disparities: 64}");
    Matcher dense = makeMatcher("sgm", "{num_disparities: 64, fill: dense}");
    const cv::Mat s = sparse.compute(left, right), d = dense.compute(left, right);
    EXPECT_TRUE(sparse.extras().empty());
    ASSERT_EQ(dense.extras().size(), 1u);
    const NamedPlane &filled = dense.extras()[0];
    EXPECT_EQ(filled.name, "disparity_filled");
    ASSERT_EQ(filled.image.type(), CV_8UC1);
    const cv::Mat holes = s <= 0;
    EXPECT_GT(cv::countNonZero(holes), 0);
    EXPECT_EQ(cv::countNonZero(filled.image != holes), 0);
    EXPECT_EQ(cv::countNonZero(d <= 0), 0);
    const cv::Mat changed = s != d;
    EXPECT_EQ(cv::countNonZero(changed & ~holes), 0);
    const std::string refused = errorOf([] { makeMatcher("sgm", "{fill: sparse}"); });
    EXPECT_NE(refused.find("expected none or dense"), std::string::npos) << refused;
}

// Columns whose candidates all lie left of the right image have no match: invalid, as
// the ABI says (BINOCLE_INVALID_DISPARITY).
TEST(SgmPlugin, MarksPixelsWithoutCandidatesInvalid) {
    const StereoPair pair = shiftedPair({160, 80}, 20);
    RawMatcher m("sgm", "{min_disparity: 10, num_disparities: 32, median_px: 1}");
    cv::Mat d(pair.left.size(), CV_32FC1, cv::Scalar(123));
    binocle_image l = imageOf(pair.left, BINOCLE_PIXEL_GRAY8), r = imageOf(pair.right, BINOCLE_PIXEL_GRAY8);
    binocle_image out = imageOf(d, BINOCLE_PIXEL_FLOAT32);
    ASSERT_EQ(m.compute(l, r, out), BINOCLE_OK) << m.lastError();
    for (int v = 0; v < d.rows; ++v)
        for (int u = 0; u < 10; ++u) ASSERT_EQ(d.at<float>(v, u), BINOCLE_INVALID_DISPARITY) << u << "," << v;
    cv::Mat error;
    cv::absdiff(d(cv::Rect(40, 0, 100, 80)), 20.0, error);
    EXPECT_GT(cv::countNonZero(error < 0.5), 100 * 80 * 0.9);
}

// The SDK's settings checker (binocle/settings.hpp) refuses these in the plugin, in the
// words the host's rig validation uses.
TEST(SgmPlugin, RefusesSettingsOutOfRange) {
    const PluginRecord &record = matcherRecord("sgm");
    expectRefused<Matcher>(record, "num_disparities", "272", "num_disparities", "expected an integer multiple of 16 >= 16 <= 256");
    expectRefused<Matcher>(record, "num_disparities", "40", "num_disparities", "expected an integer multiple of 16 >= 16 <= 256");
    expectRefused<Matcher>(record, "census_width_px", "8", "census_width_px", "expected an odd integer >= 3 <= 11");
    expectRefused<Matcher>(record, "p1", "0", "p1", "expected an integer >= 1 <= 253");
    expectRefused<Matcher>(record, "uniqueness_ratio", "100", "uniqueness_ratio", "expected an integer >= 0 <= 99");
    expectRefused<Matcher>(record, "median_px", "7", "median_px", "expected an odd integer >= 1 <= 5");
    expectRefused<Matcher>(record, "paths", "6", "paths", "expected one of 4, 5, 8");
    expectRefused<Matcher>(record, "census", "sparse", "census", "expected full or centre_symmetric");
}

TEST(SgmPlugin, RefusesSettingsThatDoNotFitTogether) {
    const std::string window = errorOf([] { makeMatcher("sgm", "{census: full, census_width_px: 11, census_height_px: 7}"); });
    EXPECT_NE(window.find("census_width_px x census_height_px = 11 x 7: expected a window of at most 64 census bits"),
              std::string::npos) << window;
    const std::string order = errorOf([] { makeMatcher("sgm", "{p1: 50, p2: 40}"); });
    EXPECT_NE(order.find("p2 = 40: expected more than p1 = 50"), std::string::npos) << order;
    const std::string range = errorOf([] { makeMatcher("sgm", "{census: full, p2: 200}"); });
    EXPECT_NE(range.find("p2 = 200: expected at most 193 = 255 - the census window's 62 bits"), std::string::npos) << range;
    EXPECT_NO_THROW(makeMatcher("sgm", "{census: full, census_width_px: 5, census_height_px: 5, p2: 230}"));
    // The centre-symmetric census has half the bits: 31 for 9 x 7, 38 for 11 x 7.
    const std::string symmetric = errorOf([] { makeMatcher("sgm", "{census: centre_symmetric, p2: 230}"); });
    EXPECT_NE(symmetric.find("p2 = 230: expected at most 224 = 255 - the census window's 31 bits"), std::string::npos)
        << symmetric;
    EXPECT_NO_THROW(makeMatcher("sgm", "{census: centre_symmetric, census_width_px: 11, census_height_px: 7, p2: 200}"));
}

TEST(SgmPlugin, RefusesAPairWhoseVolumeWouldNotFit) {
    const cv::Mat big(1000, 1200, CV_8UC1, cv::Scalar(9));
    cv::Mat d(big.size(), CV_32FC1);
    RawMatcher m("sgm", "{num_disparities: 256, max_memory_mb: 100}");
    binocle_image in = imageOf(big, BINOCLE_PIXEL_GRAY8), out = imageOf(d, BINOCLE_PIXEL_FLOAT32);
    EXPECT_EQ(m.compute(in, in, out), BINOCLE_ERR_INVALID_ARGUMENT);
    const std::string e = m.lastError();
    EXPECT_NE(e.find("1200x1000 pair with num_disparities 256 needs about"), std::string::npos) << e;
    EXPECT_NE(e.find("expected at most max_memory_mb = 100"), std::string::npos) << e;
}

TEST(SgmPlugin, RefusesInputsTheAbiRulesOut) {
    const cv::Mat grey(40, 60, CV_8UC1, cv::Scalar(1)), small(40, 59, CV_8UC1, cv::Scalar(1));
    cv::Mat d(40, 60, CV_32FC1);
    RawMatcher m("sgm", "{num_disparities: 16}");
    binocle_image l = imageOf(grey, BINOCLE_PIXEL_GRAY8), r = imageOf(small, BINOCLE_PIXEL_GRAY8);
    binocle_image out = imageOf(d, BINOCLE_PIXEL_FLOAT32);
    EXPECT_EQ(m.compute(l, r, out), BINOCLE_ERR_INVALID_ARGUMENT);
    EXPECT_NE(m.lastError().find("right image is 59x40: expected 60x40"), std::string::npos) << m.lastError();
    binocle_image g16 = imageOf(grey, BINOCLE_PIXEL_GRAY16);
    EXPECT_EQ(m.compute(g16, g16, out), BINOCLE_ERR_INVALID_ARGUMENT);
    EXPECT_NE(m.lastError().find("left image is GRAY16: expected GRAY8, BGR8 or RGB8"), std::string::npos) << m.lastError();
}

// The rigs that ship with sgm run as written, from the command line.
TEST(SgmPlugin, ItsRigsRun) {
    TempDir out;
    const CommandResult r = runCli("run " BINOCLE_SOURCE_DIR "/configs/rigs/sim-e1-sgm.yaml --frames 1 --quiet --out " + out.str());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream in(out.str("summary.json"));
    const std::string summary((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(summary.find("\"matcher\": \"sgm\""), std::string::npos) << summary;
    EXPECT_NE(summary.find("\"status\": \"ok\""), std::string::npos) << summary;
}

} // namespace
} // namespace binocle::test
