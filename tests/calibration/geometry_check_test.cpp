// SPDX-License-Identifier: MIT
// The geometry check before the first frame: a calibration for another image size,
// another baseline or with left and right swapped is refused, directly and through
// `binocle run` on a sim rig.
#include "calibration/geometry_check.hpp"
#include "common/test_util.hpp"
#include "core/error.hpp"

#include <gtest/gtest.h>

using namespace binocle;
using binocle::test::runCli;
using binocle::test::TempDir;
using binocle::test::writeText;

namespace {

std::string refusal(const StereoCalibration &c, const GeometryExpectation &e) {
    try {
        checkGeometry(c, e, "calibration calib_B150_f8.yml");
    } catch (const Error &err) {
        return err.what();
    }
    return "";
}

GeometryExpectation sim320(std::optional<double> baseline) {
    GeometryExpectation e;
    e.image_size = cv::Size(320, 240);
    e.baseline_mm = baseline;
    e.source = "sim";
    return e;
}

TEST(GeometryCheck, AgreeingCalibrationPasses) {
    const StereoCalibration c = StereoCalibration::ideal({320, 240}, 384.6, 150);
    EXPECT_EQ(refusal(c, sim320(150)), "");
    EXPECT_EQ(refusal(c, sim320(std::nullopt)), ""); // the rig states no baseline: size and sign only
    EXPECT_EQ(refusal(c, sim320(154)), "");          // within 5 %
    EXPECT_TRUE(geometryDisagreements(c, sim320(150), "x").empty());
}

TEST(GeometryCheck, OtherImageSizeIsRefused) {
    const StereoCalibration c = StereoCalibration::ideal({640, 480}, 769, 150);
    EXPECT_EQ(refusal(c, sim320(150)), "calibration calib_B150_f8.yml is for 640x480 images but source 'sim' delivers 320x240");
}

TEST(GeometryCheck, OtherBaselineIsRefused) {
    const StereoCalibration c = StereoCalibration::ideal({320, 240}, 384.6, 190.2);
    const std::string e = refusal(c, sim320(150));
    EXPECT_NE(e.find("calibration calib_B150_f8.yml: baseline 190.2 mm but the rig says baseline_mm: 150"), std::string::npos) << e;
    EXPECT_NE(refusal(StereoCalibration::ideal({320, 240}, 384.6, 140), sim320(150)).find("baseline 140 mm"), std::string::npos);
    GeometryExpectation loose = sim320(150);
    loose.baseline_tolerance = 0.3;
    EXPECT_EQ(refusal(c, loose), "");
}

TEST(GeometryCheck, SwappedCamerasAreRefused) {
    StereoCalibration c = StereoCalibration::ideal({320, 240}, 384.6, 150);
    c.T.at<double>(0) = 150;
    const std::string e = refusal(c, sim320(150));
    EXPECT_NE(e.find("T.x > 0"), std::string::npos) << e;
    EXPECT_NE(e.find("left and right are swapped"), std::string::npos) << e;
}

TEST(GeometryCheck, EveryDisagreementIsNamed) {
    StereoCalibration c = StereoCalibration::ideal({640, 480}, 769, 190);
    c.T.at<double>(0) = 190;
    const auto problems = geometryDisagreements(c, sim320(150), "calibration c.yml");
    ASSERT_EQ(problems.size(), 3u);
    EXPECT_NE(problems[0].find("640x480"), std::string::npos);
    EXPECT_NE(problems[1].find("swapped"), std::string::npos);
    EXPECT_NE(problems[2].find("baseline_mm: 150"), std::string::npos);
}

// `binocle run` on a sim rig (320x240, baseline 150 mm) with a calibration file that does
// not fit: refused before the first frame, nothing but the failed summary written.
class RunRefusesCalibration : public ::testing::Test {
protected:
    std::string rigWith(const StereoCalibration &c, const std::string &name) {
        c.save(dir_.str(name));
        const std::string rig = dir_.str("rig.yaml");
        writeText(rig, "name: sim-check\n"
                       "source:\n  plugin: sim\n  baseline_mm: 150\n  focal_length_mm: 8\n  frames: 1\n"
                       "calibration: " + name + "\n"
                       "matcher:\n  plugin: bm\n  num_disparities: 64\n");
        return rig;
    }
    TempDir dir_;
};

TEST_F(RunRefusesCalibration, ForAnotherImageSize) {
    const auto r = runCli("run " + rigWith(StereoCalibration::ideal({640, 480}, 769.2, 150), "calib_B150_f8.yml") +
                          " --quiet --out " + dir_.str("out"));
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("calib_B150_f8.yml is for 640x480 images but source 'sim' delivers 320x240"), std::string::npos)
        << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir_.str("out/disparity_000000.png")));
}

TEST_F(RunRefusesCalibration, ForAnotherBaseline) {
    const auto r = runCli("run " + rigWith(StereoCalibration::ideal({320, 240}, 384.6, 190.2), "calib_B190_f8.yml") + " --quiet");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("calib_B190_f8.yml: baseline 190.2 mm but the rig says baseline_mm: 150"), std::string::npos)
        << r.output;
}

TEST_F(RunRefusesCalibration, AcceptsTheRightOne) {
    const auto r = runCli("run " + rigWith(StereoCalibration::ideal({320, 240}, 384.6, 150), "calib_B150_f8.yml") +
                          " --quiet --out " + dir_.str("out"));
    EXPECT_EQ(r.exit_code, 0) << r.output;
}

} // namespace
