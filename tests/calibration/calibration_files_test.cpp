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
        EXPECT_NE(std::string(e.what()).find("fuzz-length-error.yml:24:1: more follows the first YAML document here; expected one document (expected an OpenCV FileStorage YAML calibration)"), std::string::npos)
            << e.what();
    }
}

// Found by the calibration fuzz harness: OpenCV's FileStorage parser never returns on
// these files (the second is well-formed YAML: one long plain scalar), and a SIGTERM
// could not end the run that read one. Calibrations are now read with the strict YAML
// loader alone, so both are refused at once, naming file, line and column.
TEST(CalibrationReader, TextThatHangsOpenCvsParserIsRefused) {
    const std::pair<const char *, const char *> cases[] = {
        {"opencv-filestorage-hang.yml",
         "opencv-filestorage-hang.yml:1:17: byte 0x93 is not valid UTF-8; expected a UTF-8 text (YAML files are UTF-8) "
         "(expected an OpenCV FileStorage YAML calibration)"},
        {"opencv-filestorage-hang-2.yml",
         "opencv-filestorage-hang-2.yml: not a calibration: expected a map of keys (image_width, image_height, M1, D1, "
         "M2, D2, R, T)"},
        // yaml-cpp's LoadAll (which parseYaml used for a while) looped for ever on this one.
        {"yaml-cpp-loadall-loop.yml",
         "yaml-cpp-loadall-loop.yml:5:1: more follows the first YAML document here; expected one document (expected an "
         "OpenCV FileStorage YAML calibration)"}};
    for (const auto &[name, expected] : cases) {
        std::ostringstream text;
        text << std::ifstream(std::string(BINOCLE_SOURCE_DIR) + "/tests/data/bad_calibration/" + name, std::ios::binary).rdbuf();
        ASSERT_FALSE(text.str().empty()) << name;
        // A hang would stall the whole suite: the read runs aside and the test gives up on it.
        auto read = std::async(std::launch::async, [s = text.str(), n = std::string(name)]() -> std::string {
            try {
                StereoCalibration::fromYaml(s, n);
                return "accepted";
            } catch (const Error &e) {
                return e.what();
            }
        });
        if (read.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
            ADD_FAILURE() << "reading " << name << " did not end within 10 s";
            std::_Exit(1); // the reading thread cannot be stopped
        }
        EXPECT_EQ(read.get(), expected);
    }
}

std::string readError(const std::string &text) {
    try {
        StereoCalibration::fromYaml(text, "c.yml");
        return "";
    } catch (const Error &e) {
        return e.what();
    }
}

// What FileStorage writes (toYaml) reads back to the same calibration; each way a file can
// be wrong is named with its key and, where there is one, its line and column.
TEST(CalibrationReader, ReadsWhatOpenCvWritesAndSaysWhereAFileIsWrong) {
    StereoCalibration c = StereoCalibration::ideal({320, 240}, 400, 150);
    c.rectified = false;
    c.D1 = (cv::Mat_<double>(1, 5) << -0.1, 0.01, 0.001, -0.002, 0);
    c.D2 = c.D1.clone();
    c.rms_px = 0.25;
    c.configuration = "B150_f8";
    c.computeRectification();
    const std::string text = c.toYaml();
    ASSERT_EQ(text.rfind("%YAML:1.0", 0), 0u) << text;
    const StereoCalibration back = StereoCalibration::fromYaml(text, "c.yml");
    EXPECT_EQ(back.image_size, c.image_size);
    EXPECT_FALSE(back.rectified);
    EXPECT_EQ(back.configuration, "B150_f8");
    EXPECT_DOUBLE_EQ(back.rms_px, 0.25);
    for (const auto &[a, b] : {std::pair<const cv::Mat *, const cv::Mat *>{&c.M1, &back.M1}, {&c.D1, &back.D1}, {&c.M2, &back.M2},
                               {&c.D2, &back.D2}, {&c.R, &back.R}, {&c.T, &back.T}, {&c.P1, &back.P1}, {&c.Q, &back.Q}}) {
        ASSERT_EQ(a->size(), b->size());
        EXPECT_EQ(cv::norm(*a, *b, cv::NORM_INF), 0.0);
    }
    const std::string head = "image_width: 64\nimage_height: 48\nrectified: 1\n";
    const std::string m = "!!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 50., 0., 32., 0., 50., 24., 0., 0., 1. ]\n";
    const std::string rt = "R: !!opencv-matrix {rows: 3, cols: 3, dt: d, data: [1., 0., 0., 0., 1., 0., 0., 0., 1.]}\n"
                           "T: !!opencv-matrix {rows: 3, cols: 1, dt: d, data: [-100., 0., 0.]}\n";
    EXPECT_EQ(readError(head + "M1: " + m + "M2: " + m + rt), "");
    EXPECT_EQ(readError(head + "rectifed: 1\nM1: " + m + "M2: " + m + rt),
              "c.yml:4:1: unknown key 'rectifed' in a calibration; did you mean 'rectified'? (valid keys: image_width, "
              "image_height, configuration, rectified, M1, D1, M2, D2, R, T, R1, R2, P1, P2, Q, baseline_mm, focal_length_px, rms_px, source)");
    EXPECT_EQ(readError(head + "M1: " + m + "M2: " + m + rt + "T: [1, 2, 3]\n"),
              "c.yml:16:1: key 'T' given twice in one map: first at 15:1, again at 16:1; remove one of them (expected an OpenCV "
              "FileStorage YAML calibration)");
    std::string wrong = m;
    wrong.replace(wrong.find("50., 0., 32."), 12, "50., 0x10, 32.");
    EXPECT_EQ(readError(head + "M1: " + wrong + "M2: " + m + rt), "c.yml:8:17: calibration key 'M1' = '0x10': expected a decimal number (0x10 is hexadecimal: write 16)");
    wrong = m;
    wrong.replace(wrong.find(", 1. ]"), 6, " ]");
    EXPECT_EQ(readError(head + "M1: " + wrong + "M2: " + m + rt), "c.yml:8:10: calibration key 'M1': expected 'data' to hold 9 numbers (rows x cols), it holds 8");
    wrong = m;
    wrong.replace(wrong.find("dt: d"), 5, "dt: u");
    EXPECT_EQ(readError(head + "M1: " + wrong + "M2: " + m + rt), "c.yml:7:8: calibration key 'M1': dt 'u': expected d (double) or f (float)");
    wrong = m;
    wrong.replace(wrong.find("rows: 3"), 7, "rows: 03");
    EXPECT_EQ(readError(head + "M1: " + wrong + "M2: " + m + rt), "c.yml: calibration key 'M1' is not a small OpenCV matrix (expected !!opencv-matrix with 3x3)");
    EXPECT_EQ(readError(head + "rms_px: .5e\nM1: " + m + "M2: " + m + rt),
              "c.yml:4:9: calibration key 'rms_px' = '.5e': expected a decimal number (the exponent has no digits)");
    EXPECT_EQ(readError("- 1\n- 2\n"), "c.yml: not a calibration: expected a map of keys (image_width, image_height, M1, D1, M2, D2, R, T)");
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
