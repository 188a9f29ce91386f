// SPDX-License-Identifier: MIT
// What `binocle calibrate` writes: configuration names, ROS camera_info YAML, the set of files.
#include "calibration/calibration_files.hpp"
#include "common/test_util.hpp"
#include "core/calibration.hpp"
#include "core/error.hpp"

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <future>
#include <sstream>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

using namespace binocle;
using binocle::test::TempDir;

namespace {

// Found by the calibration fuzz harness: OpenCV's FileStorage parser threw
// std::length_error on this mangled file, past the reader's catch (a crash in the harness,
// a cryptic "basic_string::_M_create" at the CLI). Now a clear binocle::Error naming it
// (since the strict YAML loader reads calibrations first, it stops at a second document).
TEST(CalibrationReader, ParserFailuresOfOpenCvAreBadInputNamingTheFile) {
    const std::string path = std::string(BINOCLE_SOURCE_DIR) + "/tests/data/bad_calibration/fuzz-length-error.yml";
    std::ostringstream text;
    text << std::ifstream(path, std::ios::binary).rdbuf();
    ASSERT_FALSE(text.str().empty()) << path;
    try {
        StereoCalibration::fromYaml(text.str(), "fuzz-length-error.yml");
        FAIL() << "the mangled calibration was accepted";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("fuzz-length-error.yml:26:1: a second YAML document begins here; expected one document (expected an OpenCV FileStorage YAML calibration)"), std::string::npos)
            << e.what();
    }
}

// Found by the calibration fuzz harness: OpenCV's FileStorage parser never returned on
// this 108-byte file (and a SIGTERM could not end the run that read it). The strict YAML
// loader reads a calibration first, so it is refused at once, naming file, line and byte.
TEST(CalibrationReader, TextThatHangsOpenCvsParserIsRefusedBeforeIt) {
    const std::string path = std::string(BINOCLE_SOURCE_DIR) + "/tests/data/bad_calibration/opencv-filestorage-hang.yml";
    std::ostringstream text;
    text << std::ifstream(path, std::ios::binary).rdbuf();
    ASSERT_EQ(text.str().size(), 108u) << path;
    // A hang would stall the whole suite: the read runs aside and the test gives up on it.
    auto read = std::async(std::launch::async, [s = text.str()]() -> std::string {
        try {
            StereoCalibration::fromYaml(s, "opencv-filestorage-hang.yml");
            return "accepted";
        } catch (const Error &e) {
            return e.what();
        }
    });
    if (read.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
        ADD_FAILURE() << "reading the calibration did not end within 10 s";
        std::_Exit(1); // the reading thread cannot be stopped
    }
    EXPECT_EQ(read.get(), "opencv-filestorage-hang.yml:1:17: byte 0x93 is not valid UTF-8; expected a UTF-8 text "
                          "(YAML files are UTF-8) (expected an OpenCV FileStorage YAML calibration)");
}

TEST(CalibrationFiles, ConfigurationNames) {
    EXPECT_EQ(configurationName(150.3, 8.0, 384.6), "B150_f8");
    EXPECT_EQ(configurationName(99.6, 2.8, 134.6), "B100_f2.8");
    EXPECT_EQ(configurationName(190, 12.04, 577), "B190_f12");
    EXPECT_EQ(configurationName(83.27, std::nullopt, 532.6), "B83_f533px");
}

TEST(CalibrationFiles, CameraInfoIsRosYaml) {
    StereoCalibration c = StereoCalibration::ideal({320, 240}, 400, 150);
    c.rectified = false;
    c.D1 = (cv::Mat_<double>(1, 5) << -0.1, 0.01, 0.001, -0.002, 0);
    c.D2 = c.D1.clone();
    c.computeRectification();
    for (bool right : {false, true}) {
        const YAML::Node n = YAML::Load(cameraInfoYaml(c, right, right ? "right" : "left"));
        EXPECT_EQ(n["image_width"].as<int>(), 320);
        EXPECT_EQ(n["image_height"].as<int>(), 240);
        EXPECT_EQ(n["camera_name"].as<std::string>(), right ? "right" : "left");
        EXPECT_EQ(n["distortion_model"].as<std::string>(), "plumb_bob");
        EXPECT_EQ(n["camera_matrix"]["rows"].as<int>(), 3);
        EXPECT_EQ(n["camera_matrix"]["cols"].as<int>(), 3);
        EXPECT_EQ(n["camera_matrix"]["data"].size(), 9u);
        EXPECT_DOUBLE_EQ(n["camera_matrix"]["data"][0].as<double>(), 400);
        EXPECT_EQ(n["distortion_coefficients"]["data"].size(), 5u);
        EXPECT_DOUBLE_EQ(n["distortion_coefficients"]["data"][0].as<double>(), -0.1);
        EXPECT_EQ(n["rectification_matrix"]["data"].size(), 9u);
        EXPECT_EQ(n["projection_matrix"]["rows"].as<int>(), 3);
        EXPECT_EQ(n["projection_matrix"]["cols"].as<int>(), 4);
        ASSERT_EQ(n["projection_matrix"]["data"].size(), 12u);
        // ROS: Tx = -fx' * B with B in metres, on the right camera only.
        const double tx = n["projection_matrix"]["data"][3].as<double>();
        if (right) EXPECT_NEAR(tx, -c.P2.at<double>(0, 0) * 0.150, 1e-6);
        else EXPECT_EQ(tx, 0.0);
    }
}

TEST(CalibrationFiles, WritesTheSetBesideTheCalibration) {
    TempDir dir;
    const CalibrationFiles f = CalibrationFiles::beside(dir.str("sub/calib_B150_f8.yml"));
    EXPECT_EQ(f.left_info, dir.str("sub/calib_B150_f8_left.yaml"));
    EXPECT_EQ(f.right_info, dir.str("sub/calib_B150_f8_right.yaml"));
    EXPECT_EQ(f.report, dir.str("sub/calib_B150_f8_report.json"));
    const StereoCalibration c = StereoCalibration::ideal({320, 240}, 400, 150);
    writeCalibrationFiles(f, c, Json{{"rms_px", 0.1}});
    for (const auto &p : {f.calibration, f.left_info, f.right_info, f.report}) EXPECT_TRUE(std::filesystem::exists(p)) << p;
    EXPECT_NEAR(StereoCalibration::load(f.calibration).baselineMm(), 150, 1e-9);
    size_t entries = 0;
    for ([[maybe_unused]] const auto &e : std::filesystem::directory_iterator(dir.str("sub"))) ++entries;
    EXPECT_EQ(entries, 4u); // no temporary left behind
}

} // namespace
