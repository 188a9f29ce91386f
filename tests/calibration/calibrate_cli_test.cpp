// SPDX-License-Identifier: MIT
// `binocle calibrate` end to end: opencv-doc's pairs from a folder and through a replay
// rig, the sim's board through its rig, live capture, and bad input (clear error,
// non-zero exit, nothing written).
#include "common/test_util.hpp"
#include "core/calibration.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

using binocle::test::runCli;
using binocle::test::runCommand;
using binocle::test::TempDir;
using binocle::test::writeText;
namespace fs = std::filesystem;

namespace {

const std::string kData = BINOCLE_OPENCV_DATA_DIR;

// opencv-doc's 13 pairs, plus pair 99 without a board (a 640x480 crop of the aloe scene).
void docPairsWithABoardlessOne(const TempDir &dir, bool boardless = true) {
    for (const char *n : {"01", "02", "03", "04", "05", "06", "07", "08", "09", "11", "12", "13", "14"})
        for (const std::string side : {"left", "right"})
            fs::copy_file(kData + "/" + side + n + ".jpg", dir.path() / (side + n + ".jpg"));
    if (!boardless) return;
    cv::imwrite(dir.str("left99.png"), cv::imread(kData + "/aloeL.jpg")(cv::Rect(100, 100, 640, 480)));
    cv::imwrite(dir.str("right99.png"), cv::imread(kData + "/aloeR.jpg")(cv::Rect(100, 100, 640, 480)));
}

size_t filesIn(const fs::path &dir) {
    size_t n = 0;
    for ([[maybe_unused]] const auto &e : fs::directory_iterator(dir)) ++n;
    return n;
}

std::string slurp(const std::string &path) { return runCommand("cat '" + path + "'").output; }

TEST(CalibrateCli, HasHelp) {
    const auto r = runCli("calibrate --help");
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.output.find("usage: binocle calibrate"), std::string::npos) << r.output;
    EXPECT_NE(runCli("--help").output.find("calibrate"), std::string::npos);
}

TEST(CalibrateCli, OpenCvDocPairsWriteCalibrationCameraInfoAndReport) {
    TempDir pairs, out;
    docPairsWithABoardlessOne(pairs);
    const auto r = runCli("calibrate --pairs " + pairs.str() + " --board 9x6 --square-mm 25 --out " + out.str("calib.yml"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // The pair without a board is rejected, and says why; the others are used.
    EXPECT_NE(r.output.find("pair 99    rejected: 9x6 board not found in either image"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("over 13 of 14 pairs"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("baseline |T| 83."), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("overall RMS reprojection error 0.3"), std::string::npos) << r.output;

    for (const char *f : {"calib.yml", "calib_left.yaml", "calib_right.yaml", "calib_report.json"})
        EXPECT_TRUE(fs::exists(out.path() / f)) << f;
    EXPECT_EQ(filesIn(out.path()), 4u);
    const binocle::StereoCalibration c = binocle::StereoCalibration::load(out.str("calib.yml"));
    EXPECT_EQ(c.image_size, cv::Size(640, 480));
    EXPECT_GT(c.rms_px, 0.0);
    EXPECT_LT(c.rms_px, 1.0);
    EXPECT_FALSE(c.rectified);

    const YAML::Node left = YAML::LoadFile(out.str("calib_left.yaml")), right = YAML::LoadFile(out.str("calib_right.yaml"));
    EXPECT_EQ(left["camera_name"].as<std::string>(), "left");
    EXPECT_EQ(right["camera_name"].as<std::string>(), "right");
    EXPECT_EQ(right["image_width"].as<int>(), 640);
    EXPECT_EQ(right["distortion_model"].as<std::string>(), "plumb_bob");
    EXPECT_EQ(right["projection_matrix"]["data"].size(), 12u);
    EXPECT_NEAR(right["camera_matrix"]["data"][0].as<double>(), c.M2.at<double>(0, 0), 1e-6);

    const std::string report = slurp(out.str("calib_report.json"));
    for (const char *key : {"\"rms_px\"", "\"baseline_mm\"", "\"focal_length_px\"", "\"error_px\"", "\"rejected\"", "\"id\": \"99\"",
                            "board not found in either image"})
        EXPECT_NE(report.find(key), std::string::npos) << key << "\n" << report;
}

TEST(CalibrateCli, NamesTheFileAfterTheConfiguration) {
    TempDir pairs, cwd;
    docPairsWithABoardlessOne(pairs, false);
    // No rig, no pixel pitch: B from |T|, f in px.
    auto r = runCommand("cd " + cwd.str() + " && BINOCLE_PLUGIN_PATH=" BINOCLE_BUILD_PLUGIN_DIR " " BINOCLE_CLI
                        " calibrate --pairs " + pairs.str() + " --board 9x6 --square-mm 25");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(fs::exists(cwd.path() / "calib_B83_f534px.yml")) << r.output;
    EXPECT_TRUE(fs::exists(cwd.path() / "calib_B83_f534px_report.json"));
    // With a pixel pitch, f in mm; an --out folder takes the default name.
    r = runCli("calibrate --pairs " + pairs.str() + " --board 9x6 --square-mm 50 --pixel-pitch-um 6 --out " + cwd.str("sub/"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(fs::exists(cwd.path() / "sub" / "calib_B166_f3.2.yml")) << r.output;
}

TEST(CalibrateCli, ReplayRigDeliversThePairs) {
    TempDir out;
    const auto r = runCli("calibrate " BINOCLE_SOURCE_DIR "/configs/calibration/opencv-doc-stereo.yaml --board 9x6 --square-mm 25 --out " +
                          out.str());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("over 13 of 13 pairs"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(out.path() / "calib_B83_f534px.yml")) << r.output;
}

// Issue 35: on a full disk (an 8 KiB tmpfs in a private mount namespace; root only) the
// calibration fails naming the disk's error, and leaves no report that reads as finished
// beside no calibration file (it used to leave the report and the camera_info files).
TEST(CalibrateCli, OnAFullDiskNoReportStandsWithoutItsCalibration) {
    if (runCommand("unshare -m true").exit_code != 0) GTEST_SKIP() << "cannot make a mount namespace here (needs root)";
    TempDir dir;
    fs::create_directories(dir.path() / "disk");
    const std::string disk = dir.str("disk");
    const auto r = runCommand("BINOCLE_PLUGIN_PATH='" + std::string(BINOCLE_BUILD_PLUGIN_DIR) +
                              "' unshare -m sh -c \"mount -t tmpfs -o size=8k tmpfs '" + disk + "' || exit 99; '" + BINOCLE_CLI +
                              "' calibrate " BINOCLE_SOURCE_DIR "/configs/calibration/opencv-doc-stereo.yaml --board 9x6 "
                              "--square-mm 25 --out '" + disk + "/c.yml'; echo exit=\\$?; ls -a '" + disk + "'\"");
    if (r.exit_code == 99 || r.output.find("exit=") == std::string::npos) GTEST_SKIP() << "cannot mount a tmpfs here: " << r.output;
    EXPECT_NE(r.output.find("exit=1"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("removed what this calibration had written before it"), std::string::npos) << r.output;
    // What the disk held at the end (ls -a): nothing of this calibration.
    for (const char *f : {"c_report.json", "c_left.yaml", "c_right.yaml", "c.yml"})
        EXPECT_EQ(r.output.find(std::string("\n") + f + "\n"), std::string::npos) << f << " was left: " << r.output;
}

TEST(CalibrateCli, SimBoardCalibratesItsConfigurationAndTheRunAcceptsIt) {
    TempDir out;
    auto r = runCli("calibrate " BINOCLE_SOURCE_DIR "/configs/calibration/sim-board.yaml --board 9x6 --square-mm 25 --out " +
                    out.str());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ASSERT_TRUE(fs::exists(out.path() / "calib_B150_f8.yml")) << r.output; // named after the rig's configuration
    EXPECT_NE(r.output.find("= 8.0"), std::string::npos) << r.output;      // focal length in mm from the pixel pitch
    // The same head looking at the E1 panel, rectified with that file.
    writeText(out.str("rig.yaml"), "name: sim-calibrated\n"
                                   "source:\n  plugin: sim\n  baseline_mm: 150\n  focal_length_mm: 8\n"
                                   "  distortion: [-0.18, 0.09, 0.0008, -0.0005, 0]\n"
                                   "  distortion_right: [-0.15, 0.06, -0.0006, 0.0004, 0]\n"
                                   "  right_rotation_deg: [0.4, -0.3, 0.6]\n  right_offset_mm: [0, 1.5, -1]\n"
                                   "calibration: calib_B150_f8.yml\n"
                                   "matcher:\n  plugin: sgbm\n  num_disparities: 64\n");
    r = runCli("run " + out.str("rig.yaml") + " --quiet --out " + out.str("run"));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    // Another configuration of the same rig is refused by the same calibration file.
    r = runCli("run " + out.str("rig.yaml") + " --quiet --set source.baseline_mm=190");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("but the rig says baseline_mm: 190"), std::string::npos) << r.output;
}

TEST(CalibrateCli, LiveTakesAPairWhenTheBoardIsStill) {
    // A replayed "video": each of 7 poses held for 4 frames.
    TempDir frames, out;
    int k = 0;
    for (const char *n : {"01", "02", "03", "04", "05", "06", "07"})
        for (int repeat = 0; repeat < 4; ++repeat, ++k)
            for (const std::string side : {"left", "right"}) {
                char name[32];
                std::snprintf(name, sizeof name, "%s_%03d.jpg", side.c_str(), k);
                fs::copy_file(kData + "/" + side + n + ".jpg", frames.path() / name);
            }
    writeText(frames.str("rig.yaml"), "name: live\nsource:\n  plugin: replay\n  layout: glob\n  left: left_*.jpg\n"
                                      "  right: right_*.jpg\n  color: gray\nmatcher:\n  plugin: bm\n");
    const auto r = runCli("calibrate " + frames.str("rig.yaml") +
                          " --live --still-frames 3 --pairs-wanted 5 --board 9x6 --square-mm 25 --out " + out.str("c.yml"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string report = slurp(out.str("c_report.json"));
    EXPECT_NE(report.find("\"pairs_used\": 5"), std::string::npos) << report;
    // The third frame of each pose is taken, and capture stops at 5 good pairs.
    EXPECT_NE(r.output.find("pair 2     board found"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("pair 18    board found"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("pair 22 "), std::string::npos) << r.output;
}

TEST(CalibrateCli, BadInputFailsClearlyAndWritesNothing) {
    TempDir empty, cwd, pairs;
    const std::string cli = "cd " + cwd.str() + " && BINOCLE_PLUGIN_PATH=" BINOCLE_BUILD_PLUGIN_DIR " " BINOCLE_CLI " calibrate ";
    docPairsWithABoardlessOne(pairs);

    auto r = runCommand(cli + "--pairs " + empty.str() + " --board 9x6 --square-mm 25");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("no image pairs found"), std::string::npos) << r.output;

    // Usage mistakes: exit status 2.
    r = runCommand(cli + "--pairs " + pairs.str() + " --board 9by6 --square-mm 25");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--board '9by6': expected COLSxROWS"), std::string::npos) << r.output;

    r = runCommand(cli + "--pairs " + pairs.str() + " --board 9x6");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--square-mm is required"), std::string::npos) << r.output;

    r = runCommand(cli + "--pairs /nonexistent/pairs --board 9x6 --square-mm 25");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("--pairs /nonexistent/pairs: not a folder"), std::string::npos) << r.output;

    r = runCommand(cli + "--board 9x6 --square-mm 25");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("expected a rig file"), std::string::npos) << r.output;

    // Too few usable pairs: the reasons, and no calibration.
    TempDir few;
    for (const std::string f : {"left01.jpg", "right01.jpg", "left02.jpg", "right02.jpg"}) fs::copy_file(kData + "/" + f, few.path() / f);
    fs::copy_file(pairs.path() / "left99.png", few.path() / "left03.png");
    fs::copy_file(pairs.path() / "right99.png", few.path() / "right03.png");
    r = runCommand(cli + "--pairs " + few.str() + " --board 9x6 --square-mm 25 --out out.yml");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("only 2 usable pair(s) out of 3"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("board not found in either image"), std::string::npos) << r.output;

    EXPECT_EQ(filesIn(cwd.path()), 0u); // nothing written, not even half
}

} // namespace
