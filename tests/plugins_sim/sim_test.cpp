// SPDX-License-Identifier: MIT
// The sim source plugin through the host: settings, frames, extras, metadata,
// calibration, end of stream, errors, and cv::StereoSGBM against its ground truth.
#include "common/test_util.hpp"
#include "core/calibration.hpp"
#include "plugins_matchers/plugin_fixtures.hpp" // builtPlugins(), errorOf()

#include <binocle/abi.h>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <iostream>
#include <memory>

namespace binocle::test {
namespace {

const PluginRecord &simRecord() { return builtPlugins().require("sim", BINOCLE_KIND_STEREO_SOURCE); }

std::unique_ptr<Source> makeSim(const std::string &yaml = "{}") {
    auto s = std::make_unique<Source>(simRecord(), paramsFromYaml(simRecord(), yaml));
    s->start();
    return s;
}

TEST(SimPlugin, DefaultFrameIsTheVidereHeadBeforeTheE1Panel) {
    auto src = makeSim();
    auto f = src->grab();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->left().size(), cv::Size(320, 240));
    EXPECT_EQ(f->left().type(), CV_8UC1);
    EXPECT_EQ(f->right().size(), cv::Size(320, 240));
    EXPECT_EQ(f->extra("gt_disparity").type(), CV_32FC1);
    EXPECT_EQ(f->extra("gt_depth").type(), CV_32FC1);
    EXPECT_EQ(f->extra("gt_valid").type(), CV_8UC1);
    EXPECT_EQ(f->extra("gt_object_id").type(), CV_16UC1);
    EXPECT_EQ(f->extra("gt_nonocc").type(), CV_8UC1);
    EXPECT_EQ(f->extra("gt_nonocc").size(), cv::Size(320, 240));

    const YAML::Node m = YAML::Load(f->metadata());
    EXPECT_DOUBLE_EQ(m["rig"]["baseline_mm"].as<double>(), 150);
    EXPECT_DOUBLE_EQ(m["rig"]["focal_length_mm"].as<double>(), 8);
    EXPECT_DOUBLE_EQ(m["rig"]["pixel_pitch_um"].as<double>(), 20.8);
    EXPECT_NEAR(m["rig"]["focal_length_px"].as<double>(), 384.615, 1e-3);
    EXPECT_DOUBLE_EQ(m["rig"]["camera_height_mm"].as<double>(), 1500);
    EXPECT_DOUBLE_EQ(m["rig"]["inclination_deg"].as<double>(), 0);
    EXPECT_DOUBLE_EQ(m["panel"]["width_mm"].as<double>(), 2500);
    EXPECT_DOUBLE_EQ(m["panel"]["range_mm"].as<double>(), 6000);
    EXPECT_DOUBLE_EQ(m["panel"]["height_mm"].as<double>(), 2000);
    ASSERT_TRUE(m["objects"].IsSequence());
    EXPECT_EQ(m["objects"][0]["name"].as<std::string>(), "panel");
    EXPECT_EQ(m["objects"][0]["size_mm"][0].as<double>(), 2500);
    EXPECT_EQ(m["objects"][0]["parts"].size(), 9u);
    EXPECT_FALSE(src->grab()) << "frames: 1 means one frame, then end of stream";
}

// Test (4): cv::StereoSGBM on the E1 pair at 6 m (B 150 mm, f 8 mm, 320 x 240, 20.8 um)
// agrees with gt_disparity within 1 px on at least 90 % of the panel's pixels (pixels
// without a match count as bad).
TEST(SimPlugin, StereoSgbmAgreesWithTheGroundTruthOnThePanel) {
    auto src = makeSim("{range_mm: 6000}");
    auto f = src->grab();
    ASSERT_TRUE(f);
    const int panelId = YAML::Load(f->metadata())["objects"][0]["id"].as<int>();
    auto sgbm = cv::StereoSGBM::create(0, 64, 5, 8 * 25, 32 * 25, 1, 31, 10, 100, 2);
    cv::Mat fixed, disparity;
    sgbm->compute(f->left(), f->right(), fixed);
    fixed.convertTo(disparity, CV_32F, 1.0 / 16);
    const cv::Mat truth = f->extra("gt_disparity"), ids = f->extra("gt_object_id");
    int panel = 0, matched = 0, good = 0;
    for (int v = 0; v < truth.rows; ++v)
        for (int u = 0; u < truth.cols; ++u) {
            if (ids.at<uint16_t>(v, u) != panelId) continue;
            ++panel;
            const float d = disparity.at<float>(v, u);
            if (d <= 0) continue;
            ++matched;
            if (std::abs(d - truth.at<float>(v, u)) <= 1.0f) ++good;
        }
    ASSERT_GT(panel, 5000);
    const double goodRate = static_cast<double>(good) / panel;
    std::cout << "[ figures  ] SGBM (64 disparities, block 5) on the E1 panel at 6 m: " << panel << " panel pixels, "
              << 100.0 * matched / panel << " % matched, " << 100.0 * goodRate << " % within 1 px of gt_disparity, bad rate "
              << 100.0 * (1 - goodRate) << " % (unmatched counted bad), " << 100.0 * (matched - good) / std::max(matched, 1)
              << " % of the matched\n";
    RecordProperty("panel_within_1px_percent", std::to_string(100.0 * goodRate));
    EXPECT_GE(goodRate, 0.90);
}

TEST(SimPlugin, RangeMotionAndEndOfStream) {
    auto src = makeSim("{range_mm: 12000, frames: 3, forward_mm_per_frame: 500, frame_rate_hz: 10}");
    for (int i = 0; i < 3; ++i) {
        auto f = src->grab();
        ASSERT_TRUE(f) << "frame " << i;
        EXPECT_EQ(f->raw().sequence, static_cast<uint64_t>(i));
        EXPECT_EQ(f->raw().timestamp_left_ns, i * 100000000LL);
        const YAML::Node m = YAML::Load(f->metadata());
        EXPECT_DOUBLE_EQ(m["panel"]["range_mm"].as<double>(), 12000 - 500 * i);
        // The panel's face recedes in the truth too: d = f B / R.
        const float d = f->extra("gt_disparity").at<float>(119, 159);
        EXPECT_NEAR(d, 384.615385 * 150 / (12000 - 500 * i), 1e-3);
    }
    EXPECT_FALSE(src->grab());
}

TEST(SimPlugin, PaceDeliversFramesAtTheFrameRateLikeACamera) {
    // Unpaced (the default): the next frame is rendered at once, whatever the timeout.
    auto fast = makeSim("{frames: 0, frame_rate_hz: 0.5, antialias: 1}");
    EXPECT_TRUE(fast->grab(0));
    EXPECT_TRUE(fast->grab(0));
    // Paced: the first frame is due at start, the next two seconds later, so a grab that
    // may not wait is a timeout, as for a camera.
    auto paced = makeSim("{frames: 0, frame_rate_hz: 0.5, pace: true, antialias: 1}");
    auto first = paced->grab(0);
    ASSERT_TRUE(first);
    EXPECT_EQ(first->raw().timestamp_left_ns, 0);
    try {
        paced->grab(0);
        FAIL() << "grab did not wait for the frame rate";
    } catch (const binocle::PluginError &e) {
        EXPECT_EQ(e.code(), BINOCLE_ERR_TIMEOUT) << e.what();
        EXPECT_NE(std::string(e.what()).find("frame_rate_hz"), std::string::npos) << e.what();
    }
}

TEST(SimPlugin, MainObjectLateralShiftMovesThePanelAndItsTruth) {
    auto still = makeSim("{range_mm: 6000}");
    auto moved = makeSim("{range_mm: 6000, main_object_lateral_mm: 120}");
    const YAML::Node a = YAML::Load(still->grab()->metadata()), b = YAML::Load(moved->grab()->metadata());
    EXPECT_NEAR(b["panel"]["center_mm"][0].as<double>() - a["panel"]["center_mm"][0].as<double>(), 120, 1e-9);
    EXPECT_DOUBLE_EQ(b["panel"]["range_mm"].as<double>(), 6000); // range and size unchanged
    EXPECT_DOUBLE_EQ(b["panel"]["width_mm"].as<double>(), a["panel"]["width_mm"].as<double>());
}

TEST(SimPlugin, CalibrationBoardWithoutAPoseCountIsEndless) {
    auto src = makeSim("{calibration_board: {cols: 9, rows: 6, square_mm: 25, poses: 0}}");
    std::vector<std::string> origins;
    for (int i = 0; i < 15; ++i) { // more than the 12 poses of the default
        auto f = src->grab();
        ASSERT_TRUE(f) << "pose " << i;
        origins.push_back(YAML::Dump(YAML::Load(f->metadata())["board"]["origin_camera_mm"]));
    }
    std::sort(origins.begin(), origins.end());
    EXPECT_EQ(std::unique(origins.begin(), origins.end()), origins.end()) << "every frame a new pose";
    EXPECT_NE(errorOf([] { makeSim("{calibration_board: {poses: -1}}"); }).find("calibration_board.poses = '-1': expected an integer >= 0"),
              std::string::npos);
    // The framework's strict readers: an octal-looking number and an unknown key are named.
    EXPECT_NE(errorOf([] { makeSim("{calibration_board: {cols: 09}}"); }).find("without leading zeros"), std::string::npos);
    EXPECT_NE(errorOf([] { makeSim("{calibration_board: {colz: 9}}"); }).find("unknown key 'colz'; did you mean 'cols'?"),
              std::string::npos);
}

TEST(SimPlugin, PublishesItsExactCalibration) {
    auto ideal = makeSim("{baseline_mm: 100, focal_length_mm: 12}");
    const StereoCalibration c = StereoCalibration::fromYaml(ideal->calibration(), "sim");
    EXPECT_TRUE(c.rectified);
    EXPECT_NEAR(c.focalLengthPx(), 12000 / 20.8, 1e-9);
    EXPECT_NEAR(c.baselineMm(), 100, 1e-9);

    auto bent = makeSim("{distortion: [-0.1, 0.02, 0, 0], right_rotation_deg: [0.2, 0, 0.3], right_offset_mm: [0, 1, 0]}");
    const StereoCalibration d = StereoCalibration::fromYaml(bent->calibration(), "sim");
    EXPECT_FALSE(d.rectified);
    EXPECT_DOUBLE_EQ(d.D1.at<double>(0), -0.1);
    EXPECT_DOUBLE_EQ(d.D2.at<double>(1), 0.02) << "distortion_right defaults to distortion";
    EXPECT_NEAR(d.T.at<double>(0), -150, 0.5);
}

TEST(SimPlugin, ColourAndSeed) {
    auto colour = makeSim("{color: bgr, image_width: 160, image_height: 120}");
    auto f = colour->grab();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->left().type(), CV_8UC3);
    EXPECT_EQ(f->raw().left.format, BINOCLE_PIXEL_BGR8);
    // Turf is green: G above R and B on the lowest rows.
    const cv::Scalar mean = cv::mean(f->left()(cv::Rect(0, 100, 160, 20)));
    EXPECT_GT(mean[1], mean[0]);
    EXPECT_GT(mean[1], mean[2]);

    auto a = makeSim("{seed: 3}"), b = makeSim("{seed: 3}"), c = makeSim("{seed: 4}");
    auto fa = a->grab(), fb = b->grab(), fc = c->grab();
    EXPECT_EQ(cv::norm(fa->left(), fb->left(), cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(fa->right(), fb->right(), cv::NORM_INF), 0);
    EXPECT_GT(cv::norm(fa->left(), fc->left(), cv::NORM_INF), 0);
}

TEST(SimPlugin, RightImagerGainOffsetAndBinning) {
    auto even = makeSim("{noise_sigma: 0}"), dim = makeSim("{noise_sigma: 0, gain_right: 0.8, offset_right: 10}");
    auto a = even->grab(), b = dim->grab();
    EXPECT_EQ(cv::norm(a->left(), b->left(), cv::NORM_INF), 0) << "the left imager is the reference";
    // Sky (top rows, no texture): right = 0.8 * left + 10, within rounding.
    const double left = cv::mean(a->right()(cv::Rect(0, 0, 320, 20)))[0], right = cv::mean(b->right()(cv::Rect(0, 0, 320, 20)))[0];
    EXPECT_NEAR(right, 0.8 * left + 10, 0.6);

    // Binning 2: the noise of an output pixel is noise_sigma / 2.
    auto noisy = makeSim("{noise_sigma: 4, seed: 1}"), binned = makeSim("{noise_sigma: 4, seed: 1, binning: 2}");
    auto n1 = noisy->grab(), n2 = binned->grab();
    const cv::Mat clean = a->left();
    cv::Mat d1, d2;
    cv::subtract(n1->left(), clean, d1, cv::noArray(), CV_32F);
    cv::subtract(n2->left(), clean, d2, cv::noArray(), CV_32F);
    cv::Scalar m, sd1, sd2;
    cv::meanStdDev(d1(cv::Rect(0, 0, 320, 60)), m, sd1); // sky: no edges to supersample differently
    cv::meanStdDev(d2(cv::Rect(0, 0, 320, 60)), m, sd2);
    EXPECT_NEAR(sd1[0], 4.0, 0.3);
    EXPECT_NEAR(sd2[0], 2.0, 0.2);
}

TEST(SimPlugin, E2TreeSceneGivesTheMarkerPosition) {
    auto src = makeSim("{scene: '" + std::string(BINOCLE_SOURCE_DIR) + "/configs/scenes/e2_tree.yaml', range_mm: 7000}");
    auto f = src->grab();
    ASSERT_TRUE(f);
    const YAML::Node m = YAML::Load(f->metadata());
    EXPECT_EQ(m["main_object"].as<std::string>(), "marker");
    bool found = false;
    for (const auto &o : m["objects"]) {
        if (o["name"].as<std::string>() != "marker") continue;
        found = true;
        EXPECT_DOUBLE_EQ(o["range_mm"].as<double>(), 7000);
        EXPECT_DOUBLE_EQ(o["center_mm"][1].as<double>(), 7250);
        const int id = o["id"].as<int>();
        EXPECT_GT(cv::countNonZero(f->extra("gt_object_id") == id), 100) << "the marker is in view";
    }
    EXPECT_TRUE(found) << f->metadata();
}

TEST(SimPlugin, RefusesBadScenesAndSettings) {
    std::string e = errorOf([] { makeSim("{scene: /nonexistent/scene.yaml}"); });
    EXPECT_NE(e.find("/nonexistent/scene.yaml"), std::string::npos) << e;
    TempDir dir;
    writeText(dir.str("bad.yaml"), "name: bad\nobjects:\n  - name: a\n    type: box\n    center_mm: [0, 1000, 0]\n    size_mm: [1, 2]\n");
    e = errorOf([&] { makeSim("{scene: '" + dir.str("bad.yaml") + "'}"); });
    EXPECT_NE(e.find(dir.str("bad.yaml") + ":6:"), std::string::npos) << e;
    EXPECT_NE(e.find("size_mm"), std::string::npos) << e;
    e = errorOf([] { makeSim("{distortion: [0.1, 0.2]}"); });
    EXPECT_NE(e.find("distortion"), std::string::npos) << e;
    EXPECT_NE(e.find("4 or 5"), std::string::npos) << e;
    e = errorOf([] { makeSim("{calibration_board: {cols: 1, rows: 6}}"); });
    EXPECT_NE(e.find("cols"), std::string::npos) << e;
}

// Calibration mode: every pose shows the whole board to both imagers, and the corners
// OpenCV finds in the left image are where the metadata's true board pose projects.
TEST(SimPlugin, CalibrationBoardPosesAreFoundByOpenCv) {
    auto src = makeSim("{image_width: 640, image_height: 480, pixel_pitch_um: 10.4, "
                       "calibration_board: {cols: 9, rows: 6, square_mm: 25, poses: 4}}");
    const StereoCalibration c = StereoCalibration::fromYaml(src->calibration(), "sim");
    int poses = 0;
    double worst = 0;
    while (auto f = src->grab()) {
        ++poses;
        std::vector<cv::Point2f> l, r;
        ASSERT_TRUE(cv::findChessboardCorners(f->left(), cv::Size(9, 6), l)) << "left, pose " << poses;
        EXPECT_TRUE(cv::findChessboardCorners(f->right(), cv::Size(9, 6), r)) << "right, pose " << poses;
        cv::cornerSubPix(f->left(), l, cv::Size(5, 5), cv::Size(-1, -1),
                         cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 0.001));
        const YAML::Node b = YAML::Load(f->metadata())["board"];
        ASSERT_TRUE(b) << f->metadata();
        ASSERT_EQ(b["cols"].as<int>(), 9);
        ASSERT_EQ(b["rows"].as<int>(), 6);
        const double sq = b["square_mm"].as<double>();
        auto vec = [&](const char *key) { return cv::Point3d(b[key][0].as<double>(), b[key][1].as<double>(), b[key][2].as<double>()); };
        const cv::Point3d origin = vec("origin_camera_mm"), x = vec("x_axis_camera"), y = vec("y_axis_camera");
        std::vector<cv::Point3d> truth;
        for (int j = 0; j < 6; ++j)
            for (int i = 0; i < 9; ++i) truth.push_back(origin + i * sq * x + j * sq * y);
        std::vector<cv::Point2d> projected;
        cv::projectPoints(truth, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), c.M1, c.D1, projected);
        for (const cv::Point2f &p : l) {
            double nearest = 1e9;
            for (const cv::Point2d &q : projected) nearest = std::min(nearest, cv::norm(cv::Point2d(p) - q));
            worst = std::max(worst, nearest);
        }
    }
    EXPECT_EQ(poses, 4);
    EXPECT_LT(worst, 0.3) << "detected corners against the metadata's board pose";
    std::cout << "[ figures  ] calibration board: largest corner error (cornerSubPix vs true pose) " << worst << " px\n";
}

} // namespace
} // namespace binocle::test
