// SPDX-License-Identifier: MIT
// Tests of the replay source plugin, loaded through the plugin host, on data each test writes.
#include "replay_fixture.hpp"

#include "config/rig_config.hpp"
#include "core/calibration.hpp"
#include "core/error.hpp"
#include "core/image_io.hpp"
#include "host/plugin_host.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>


namespace {

cv::FileStorage readCalibration(const std::string &text) {
    return cv::FileStorage(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
}

cv::Mat matrix(const cv::FileStorage &fs, const char *key) {
    cv::Mat m;
    fs[key] >> m;
    return m;
}

std::string q(const fs::path &p) { return "'" + p.string() + "'"; }

// ---- glob layout --------------------------------------------------------------------------

TEST_F(Replay, GlobPlaysPairsInNaturalOrderWithTheFilesPixels) {
    const cv::Size size(32, 24);
    const std::vector<int> numbers{10, 2, 1, 11, 3};
    for (int n : numbers) {
        write(path("left_" + std::to_string(n) + ".png"), noise(size, CV_8UC3, n));
        write(path("right_" + std::to_string(n) + ".png"), noise(size, CV_8UC3, 100 + n));
    }
    auto src = open("{left: " + path("left_*.png").string() + ", right: " + path("right_*.png").string() + "}");
    const std::vector<int> expected{1, 2, 3, 10, 11};
    for (size_t i = 0; i < expected.size(); ++i) {
        auto f = src->grab();
        ASSERT_TRUE(f) << "frame " << i;
        EXPECT_EQ(f->raw().sequence, i);
        EXPECT_EQ(f->raw().left.format, BINOCLE_PIXEL_BGR8);
        EXPECT_TRUE(equal(f->left(), noise(size, CV_8UC3, expected[i]))) << "left of frame " << i;
        EXPECT_TRUE(equal(f->right(), noise(size, CV_8UC3, 100 + expected[i]))) << "right of frame " << i;
        EXPECT_EQ(f->raw().extra_count, 0);
        // No rate and no recorded time: sequence times a nominal 30 Hz period.
        EXPECT_EQ(f->raw().timestamp_left_ns, static_cast<int64_t>(i) * 33333333);
        EXPECT_EQ(f->raw().timestamp_right_ns, f->raw().timestamp_left_ns);
        EXPECT_EQ(metadataOf(*f)["left_file"].as<std::string>(),
                  path("left_" + std::to_string(expected[i]) + ".png").string());
    }
    EXPECT_EQ(src->grab(), nullptr);
    EXPECT_EQ(src->grab(), nullptr);
    EXPECT_TRUE(src->calibration().empty());
    YAML::Node stats = YAML::Load(src->statistics());
    EXPECT_EQ(stats["frames"].as<int>(), 5);
    EXPECT_EQ(stats["layout"].as<std::string>(), "glob");
}

TEST_F(Replay, FramesStayValidWhileLentAndReleaseInAnyOrder) {
    const cv::Size size(8, 6);
    for (int n = 0; n < 3; ++n) {
        write(path("l/" + std::to_string(n) + ".png"), noise(size, CV_8UC3, n));
        write(path("r/" + std::to_string(n) + ".png"), noise(size, CV_8UC3, 50 + n));
    }
    auto src = open("{left: " + path("l/*.png").string() + ", right: " + path("r/*.png").string() + "}");
    std::vector<std::unique_ptr<LentFrame>> held;
    for (int n = 0; n < 3; ++n) held.push_back(src->grab());
    held.erase(held.begin() + 1);
    EXPECT_TRUE(equal(held[0]->left(), noise(size, CV_8UC3, 0)));
    EXPECT_TRUE(equal(held[1]->right(), noise(size, CV_8UC3, 52)));
}

TEST_F(Replay, ColorGrayDeliversGray8) {
    const cv::Size size(16, 12);
    write(path("a_l.png"), noise(size, CV_8UC1, 1));
    write(path("a_r.png"), noise(size, CV_8UC1, 2));
    write(path("b_l.png"), noise(size, CV_8UC3, 3)); // colour files become grey too
    write(path("b_r.png"), noise(size, CV_8UC3, 4));
    auto src = open("{left: " + path("*_l.png").string() + ", right: " + path("*_r.png").string() + ", color: gray}");
    auto a = src->grab();
    ASSERT_TRUE(a);
    EXPECT_EQ(a->raw().left.format, BINOCLE_PIXEL_GRAY8);
    EXPECT_TRUE(equal(a->left(), noise(size, CV_8UC1, 1)));
    EXPECT_TRUE(equal(a->right(), noise(size, CV_8UC1, 2)));
    auto b = src->grab();
    ASSERT_TRUE(b);
    EXPECT_EQ(b->raw().right.format, BINOCLE_PIXEL_GRAY8);
    EXPECT_TRUE(equal(b->left(), cv::imread(path("b_l.png").string(), cv::IMREAD_GRAYSCALE)));
}

TEST_F(Replay, GlobGroundTruthIn16BitPng) {
    const cv::Size size(16, 8); // disparities must be less than the width
    write(path("l0.png"), noise(size, CV_8UC3, 0));
    write(path("r0.png"), noise(size, CV_8UC3, 1));
    cv::Mat raw(size, CV_16UC1, cv::Scalar(0));
    raw.at<uint16_t>(2, 3) = 10 * 256 + 128; // 10.5 px
    raw.at<uint16_t>(4, 5) = 256;            // 1 px
    write(path("gt0.png"), raw);
    auto src = open("{left: " + path("l*.png").string() + ", right: " + path("r*.png").string() +
                    ", ground_truth: " + path("gt*.png").string() + "}");
    auto f = src->grab();
    ASSERT_TRUE(f);
    ASSERT_EQ(f->raw().extra_count, 2);
    cv::Mat d = f->extra("gt_disparity"), valid = f->extra("gt_valid");
    ASSERT_EQ(d.type(), CV_32FC1);
    ASSERT_EQ(valid.type(), CV_8UC1);
    EXPECT_FLOAT_EQ(d.at<float>(2, 3), 10.5f);
    EXPECT_FLOAT_EQ(d.at<float>(4, 5), 1.0f);
    EXPECT_LE(d.at<float>(0, 0), 0.0f);
    EXPECT_EQ(valid.at<uint8_t>(2, 3), 255);
    EXPECT_EQ(valid.at<uint8_t>(0, 0), 0);
    EXPECT_EQ(cv::countNonZero(valid), 2);
}

TEST_F(Replay, GlobGroundTruthIn8BitPngIsScaled) {
    const cv::Size size(24, 8);
    write(path("l0.png"), noise(size, CV_8UC1, 0));
    write(path("r0.png"), noise(size, CV_8UC1, 1));
    cv::Mat raw(size, CV_8UC1, cv::Scalar(40));
    raw.at<uint8_t>(1, 1) = 0;
    write(path("gt0.png"), raw);
    auto src = open("{left: " + path("l*.png").string() + ", right: " + path("r*.png").string() +
                    ", ground_truth: " + path("gt*.png").string() + ", ground_truth_scale: 0.5}");
    auto f = src->grab();
    ASSERT_TRUE(f);
    EXPECT_FLOAT_EQ(f->extra("gt_disparity").at<float>(0, 0), 20.0f);
    EXPECT_LE(f->extra("gt_disparity").at<float>(1, 1), 0.0f);
    EXPECT_EQ(f->extra("gt_valid").at<uint8_t>(1, 1), 0);
    EXPECT_EQ(cv::countNonZero(f->extra("gt_valid")), size.area() - 1);
}

TEST_F(Replay, GlobGroundTruthInPfm) {
    const cv::Size size(12, 5);
    write(path("l0.png"), noise(size, CV_8UC3, 0));
    write(path("r0.png"), noise(size, CV_8UC3, 1));
    cv::Mat d(size, CV_32FC1);
    for (int v = 0; v < size.height; ++v)
        for (int u = 0; u < size.width; ++u) d.at<float>(v, u) = 1.25f * v + 0.5f * u + 1.0f;
    d.at<float>(0, 6) = std::numeric_limits<float>::infinity();
    writePfmBigEndian(path("gt0.pfm"), d);
    auto src = open("{left: " + path("l*.png").string() + ", right: " + path("r*.png").string() +
                    ", ground_truth: " + path("gt*.pfm").string() + "}");
    auto f = src->grab();
    ASSERT_TRUE(f);
    cv::Mat got = f->extra("gt_disparity");
    EXPECT_FLOAT_EQ(got.at<float>(4, 0), 6.0f); // bottom row: the file's first
    EXPECT_FLOAT_EQ(got.at<float>(0, 1), 1.5f);
    EXPECT_LE(got.at<float>(0, 6), 0.0f);
    EXPECT_EQ(f->extra("gt_valid").at<uint8_t>(0, 6), 0);
    EXPECT_EQ(cv::countNonZero(f->extra("gt_valid")), size.area() - 1);
}

TEST_F(Replay, GlobErrorsNameThePatternsAndCounts) {
    const cv::Size size(8, 6);
    for (int n = 0; n < 3; ++n) write(path("l" + std::to_string(n) + ".png"), noise(size, CV_8UC3, n));
    for (int n = 0; n < 2; ++n) write(path("r" + std::to_string(n) + ".png"), noise(size, CV_8UC3, n));
    const std::string left = path("l*.png").string(), right = path("r*.png").string();

    std::string e = openError("{left: " + left + ", right: " + right + "}");
    EXPECT_NE(e.find("'" + left + "' matched 3"), std::string::npos) << e;
    EXPECT_NE(e.find("'" + right + "' matched 2"), std::string::npos) << e;

    const std::string none = path("nothing_*.png").string();
    e = openError("{left: " + none + ", right: " + right + "}");
    EXPECT_NE(e.find("left pattern '" + none + "' matched no file"), std::string::npos) << e;

    e = openError("{left: " + left + "}");
    EXPECT_NE(e.find("`right`"), std::string::npos) << e;

    e = openError("{left: " + left + ", right: " + left + ", first_frame: 3}");
    EXPECT_NE(e.find("first_frame 3"), std::string::npos) << e;
    EXPECT_NE(e.find("holds 3 frames"), std::string::npos) << e;
}

TEST_F(Replay, PairOfTwoSizesIsAnErrorNamingBothFiles) {
    write(path("l0.png"), noise({8, 6}, CV_8UC3, 0));
    write(path("r0.png"), noise({9, 6}, CV_8UC3, 1));
    auto src = open("{left: " + path("l*.png").string() + ", right: " + path("r*.png").string() + "}");
    try {
        src->grab();
        FAIL() << "a pair of two sizes was accepted";
    } catch (const binocle::Error &e) {
        const std::string m = e.what();
        EXPECT_NE(m.find(q(path("l0.png")) + " is 8x6"), std::string::npos) << m;
        EXPECT_NE(m.find(q(path("r0.png")) + " is 9x6"), std::string::npos) << m;
    }
}

TEST_F(Replay, LoopFirstFrameAndMaxFrames) {
    const cv::Size size(8, 6);
    for (int n = 0; n < 5; ++n) {
        write(path("l" + std::to_string(n) + ".png"), noise(size, CV_8UC3, n));
        write(path("r" + std::to_string(n) + ".png"), noise(size, CV_8UC3, 10 + n));
    }
    const std::string globs = "left: " + path("l*.png").string() + ", right: " + path("r*.png").string();
    auto src = open("{" + globs + ", first_frame: 1, max_frames: 2, loop: true}");
    const std::vector<int> expected{1, 2, 1, 2, 1};
    for (size_t i = 0; i < expected.size(); ++i) {
        auto f = src->grab();
        ASSERT_TRUE(f);
        EXPECT_EQ(f->raw().sequence, i);
        EXPECT_TRUE(equal(f->left(), noise(size, CV_8UC3, expected[i]))) << "grab " << i;
        EXPECT_EQ(metadataOf(*f)["frame_index"].as<int>(), expected[i]);
    }
    auto once = open("{" + globs + ", first_frame: 3}");
    EXPECT_TRUE(once->grab());
    EXPECT_TRUE(once->grab());
    EXPECT_EQ(once->grab(), nullptr);
}

TEST_F(Replay, RateHzPacesGrabAndTimesOut) {
    write(path("l0.png"), noise({8, 6}, CV_8UC3, 0));
    write(path("l1.png"), noise({8, 6}, CV_8UC3, 1));
    auto src = open("{left: " + path("l*.png").string() + ", right: " + path("l*.png").string() + ", rate_hz: 0.5}");
    auto first = src->grab(0); // due at start
    ASSERT_TRUE(first);
    try {
        src->grab(0); // the next one is due two seconds later
        FAIL() << "grab did not wait for the rate";
    } catch (const binocle::PluginError &e) {
        EXPECT_EQ(e.code(), BINOCLE_ERR_TIMEOUT) << e.what();
    }
    EXPECT_EQ(first->raw().timestamp_left_ns, 0);
}

TEST_F(Replay, CalibrationSettingOverridesTheLayout) {
    write(path("l0.png"), noise({8, 6}, CV_8UC3, 0));
    const std::string calib = binocle::StereoCalibration::ideal({8, 6}, 100.0, 120.0).toYaml();
    writeText(path("calib.yml"), calib);
    auto src = open("{left: " + path("l*.png").string() + ", right: " + path("l*.png").string() +
                    ", calibration: " + path("calib.yml").string() + "}");
    EXPECT_EQ(src->calibration(), calib);

    writeText(path("bad.yml"), "not: a calibration\n");
    std::string e = openError("{left: " + path("l*.png").string() + ", right: " + path("l*.png").string() +
                              ", calibration: " + path("bad.yml").string() + "}");
    EXPECT_NE(e.find(q(path("bad.yml"))), std::string::npos) << e;
}

// ---- middlebury layout ---------------------------------------------------------------------

// A scene 12x8 with doffs 2.5: cam1's cx is cam0's + 2.5.
void writeMiddleburyScene(const fs::path &scene, int seed, double baselineMm = 193.001) {
    const cv::Size size(12, 8);
    write(scene / "im0.png", noise(size, CV_8UC3, seed));
    write(scene / "im1.png", noise(size, CV_8UC3, seed + 1));
    writeText(scene / "calib.txt", "cam0=[100.5 0 6.25; 0 100.5 3.75; 0 0 1]\n"
                                   "cam1=[100.5 0 8.75; 0 100.5 3.75; 0 0 1]\n"
                                   "doffs=2.5\nbaseline=" + std::to_string(baselineMm) +
                                       "\nwidth=12\nheight=8\nndisp=64\nisint=0\nvmin=2\nvmax=40\n");
}

TEST_F(Replay, MiddleburySceneWithCalibrationAndPfmGroundTruth) {
    const fs::path scene = path("Aloe");
    writeMiddleburyScene(scene, 7);
    cv::Mat d(8, 12, CV_32FC1, cv::Scalar(10.75f));
    d.at<float>(1, 2) = std::numeric_limits<float>::infinity();
    d.at<float>(7, 0) = 3.0f;
    writePfmBigEndian(scene / "disp0.pfm", d);

    auto src = open("{folder: " + scene.string() + "}"); // layout detected
    auto f = src->grab();
    ASSERT_TRUE(f);
    EXPECT_TRUE(equal(f->left(), noise({12, 8}, CV_8UC3, 7)));
    EXPECT_TRUE(equal(f->right(), noise({12, 8}, CV_8UC3, 8)));
    cv::Mat gt = f->extra("gt_disparity");
    EXPECT_FLOAT_EQ(gt.at<float>(0, 0), 10.75f);
    EXPECT_FLOAT_EQ(gt.at<float>(7, 0), 3.0f);
    EXPECT_LE(gt.at<float>(1, 2), 0.0f);
    EXPECT_EQ(f->extra("gt_valid").at<uint8_t>(1, 2), 0);
    EXPECT_EQ(metadataOf(*f)["ndisp"].as<int>(), 64);
    EXPECT_EQ(src->grab(), nullptr);

    const std::string text = src->calibration();
    cv::FileStorage fs = readCalibration(text);
    ASSERT_TRUE(fs.isOpened()) << text;
    EXPECT_EQ(static_cast<int>(fs["image_width"]), 12);
    EXPECT_EQ(static_cast<int>(fs["image_height"]), 8);
    EXPECT_EQ(static_cast<int>(fs["rectified"]), 1);
    cv::Mat M1 = matrix(fs, "M1"), M2 = matrix(fs, "M2"), T = matrix(fs, "T");
    EXPECT_DOUBLE_EQ(M1.at<double>(0, 0), 100.5);
    EXPECT_DOUBLE_EQ(M1.at<double>(0, 2), 6.25);
    EXPECT_DOUBLE_EQ(M2.at<double>(0, 2), 8.75); // doffs kept
    EXPECT_NEAR(T.at<double>(0), -193.001, 1e-9);
    EXPECT_DOUBLE_EQ(T.at<double>(1), 0.0);

    // The framework reads it back, and its depth matches Middlebury's Z = f B / (d + doffs).
    auto calib = binocle::StereoCalibration::fromYaml(text, "replay");
    EXPECT_NEAR(calib.baselineMm(), 193.001, 1e-9);
    EXPECT_NEAR(calib.focalLengthPx(), 100.5, 1e-9);
    const double disparity = 20;
    cv::Vec4d p = cv::Matx44d(reinterpret_cast<const double *>(calib.Q.data)) * cv::Vec4d(6.25, 3.75, disparity, 1);
    EXPECT_NEAR(p[2] / p[3], 100.5 * 193.001 / (disparity + 2.5), 1e-6);
}

TEST_F(Replay, MiddleburyPfmFromTheFrameworkWriter) {
    const fs::path scene = path("scene");
    writeMiddleburyScene(scene, 1);
    cv::Mat d(8, 12, CV_32FC1);
    cv::randu(d, 1.0, 11.0); // disparities of a 12-pixel-wide image
    d.at<float>(3, 3) = std::numeric_limits<float>::infinity();
    binocle::writePfm((scene / "disp0GT.pfm").string(), d); // little-endian, MiddEval3 name
    auto src = open("{layout: middlebury, folder: " + scene.string() + "}");
    auto f = src->grab();
    ASSERT_TRUE(f);
    cv::Mat expected = d.clone();
    expected.at<float>(3, 3) = -1.0f;
    EXPECT_TRUE(equal(f->extra("gt_disparity"), expected));
}

TEST_F(Replay, MiddleburySequenceFromAGlobOrAFolderOfScenes) {
    for (int n : {10, 2, 1}) writeMiddleburyScene(path("scenes/s" + std::to_string(n)), n * 10);
    writeText(path("scenes/notes.txt"), "not a scene\n");
    for (const std::string folder : {path("scenes/s*").string(), path("scenes").string()}) {
        auto src = open("{folder: " + folder + "}");
        for (int n : {1, 2, 10}) {
            auto f = src->grab();
            ASSERT_TRUE(f) << folder;
            EXPECT_TRUE(equal(f->left(), noise({12, 8}, CV_8UC3, n * 10))) << folder << " scene " << n;
            EXPECT_EQ(metadataOf(*f)["scene"].as<std::string>(), "s" + std::to_string(n));
            EXPECT_EQ(f->raw().extra_count, 0);
        }
        EXPECT_EQ(src->grab(), nullptr) << folder;
    }
}

TEST_F(Replay, MiddleburyErrorsNameTheFolder) {
    const std::string missing = path("no_such_scene").string();
    std::string e = openError("{folder: " + missing + "}");
    EXPECT_NE(e.find("'" + missing + "'"), std::string::npos) << e;
    EXPECT_NE(e.find("does not exist"), std::string::npos) << e;

    fs::create_directories(path("empty"));
    e = openError("{layout: middlebury, folder: " + path("empty").string() + "}");
    EXPECT_NE(e.find("'" + path("empty").string() + "'"), std::string::npos) << e;
    EXPECT_NE(e.find("im0.png"), std::string::npos) << e;

    e = openError("{folder: " + path("empty").string() + "}"); // auto: lists what it looked for
    EXPECT_NE(e.find("frames.csv"), std::string::npos) << e;
    EXPECT_NE(e.find("image_2"), std::string::npos) << e;

    writeMiddleburyScene(path("bad"), 1);
    writeText(path("bad/calib.txt"), "cam0=[1 2 3]\ncam1=[100 0 5; 0 100 4; 0 0 1]\nbaseline=100\n");
    e = openError("{folder: " + path("bad").string() + "}");
    EXPECT_NE(e.find("calib.txt:1"), std::string::npos) << e;
    EXPECT_NE(e.find("cam0"), std::string::npos) << e;
}

// ---- kitti layout --------------------------------------------------------------------------

TEST_F(Replay, KittiTreeWithGroundTruthAndCalibration) {
    const cv::Size size(20, 10);
    const fs::path kitti = path("training");
    for (const char *name : {"000001_10.png", "000000_11.png", "000000_10.png"}) {
        const int seed = static_cast<int>(std::string(name).size()) + name[5] * 3 + name[8];
        write(kitti / "image_2" / name, noise(size, CV_8UC3, seed));
        write(kitti / "image_3" / name, noise(size, CV_8UC3, seed + 50));
    }
    cv::Mat raw(size, CV_16UC1, cv::Scalar(0));
    raw.at<uint16_t>(5, 5) = 13 * 256 + 64;
    write(kitti / "disp_occ_0" / "000000_10.png", raw);
    write(kitti / "disp_noc_0" / "000000_10.png", cv::Mat(size, CV_16UC1, cv::Scalar(0)));
    // KITTI 2015 style: f = 721.5377, cam2 t_x = +0.0598 m, cam3 t_x = -0.4728 m.
    writeText(kitti / "calib_cam_to_cam.txt",
              "calib_time: 09-Jan-2012 13:57:47\n"
              "S_rect_02: 2.000000e+01 1.000000e+01\n"
              "P_rect_02: 7.215377e+02 0.000000e+00 6.095593e+02 4.485728e+01 0.000000e+00 7.215377e+02 "
              "1.728540e+02 0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00\n"
              "P_rect_03: 7.215377e+02 0.000000e+00 6.095593e+02 -3.395242e+02 0.000000e+00 7.215377e+02 "
              "1.728540e+02 0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00\n");

    auto src = open("{folder: " + kitti.string() + "}");
    std::vector<std::string> names;
    while (auto f = src->grab()) {
        const std::string file = fs::path(metadataOf(*f)["left_file"].as<std::string>()).filename().string();
        names.push_back(file);
        const int seed = static_cast<int>(file.size()) + file[5] * 3 + file[8];
        EXPECT_TRUE(equal(f->left(), noise(size, CV_8UC3, seed))) << file;
        EXPECT_TRUE(equal(f->right(), noise(size, CV_8UC3, seed + 50))) << file;
        if (file == "000000_10.png") {
            ASSERT_EQ(f->raw().extra_count, 3);
            EXPECT_FLOAT_EQ(f->extra("gt_disparity").at<float>(5, 5), 13.25f); // disp_occ_0 preferred
            EXPECT_EQ(cv::countNonZero(f->extra("gt_valid")), 1);
            EXPECT_EQ(cv::countNonZero(f->extra("gt_nonocc")), 0); // disp_noc_0 knows no pixel
        } else {
            EXPECT_EQ(f->raw().extra_count, 0) << file;
        }
    }
    EXPECT_EQ(names, (std::vector<std::string>{"000000_10.png", "000000_11.png", "000001_10.png"}));

    cv::FileStorage fs = readCalibration(src->calibration());
    ASSERT_TRUE(fs.isOpened()) << src->calibration();
    const double baselineMm = (44.85728 + 339.5242) / 721.5377 * 1000.0;
    EXPECT_NEAR(-matrix(fs, "T").at<double>(0), baselineMm, 1e-6);
    EXPECT_NEAR(matrix(fs, "M1").at<double>(0, 0), 721.5377, 1e-9);
    EXPECT_NEAR(static_cast<double>(fs["baseline_mm"]), baselineMm, 1e-6);
    EXPECT_EQ(static_cast<int>(fs["image_width"]), 20);
}

TEST_F(Replay, KittiPerFrameCalibFolderAndNoCalibration) {
    const cv::Size size(6, 4);
    const fs::path kitti = path("kitti");
    for (const char *name : {"000000_10.png", "000001_10.png"}) {
        write(kitti / "image_2" / name, noise(size, CV_8UC3, 1));
        write(kitti / "image_3" / name, noise(size, CV_8UC3, 2));
    }
    auto bare = open("{layout: kitti, folder: " + kitti.string() + "}");
    EXPECT_TRUE(bare->calibration().empty());

    // Object-benchmark style calib/<frame>.txt with P2/P3; focal lengths differ per frame.
    for (const auto &[stem, f] : std::vector<std::pair<std::string, double>>{{"000000", 700.0}, {"000001", 710.0}})
        writeText(kitti / "calib" / (stem + ".txt"),
                  "P2: " + std::to_string(f) + " 0 3 " + std::to_string(f * 0.06) + " 0 " + std::to_string(f) +
                      " 2 0 0 0 1 0\nP3: " + std::to_string(f) + " 0 3 " + std::to_string(-f * 0.48) + " 0 " +
                      std::to_string(f) + " 2 0 0 0 1 0\n");
    auto src = open("{folder: " + kitti.string() + "}");
    cv::FileStorage fs = readCalibration(src->calibration());
    EXPECT_NEAR(matrix(fs, "M1").at<double>(0, 0), 700.0, 1e-9);
    EXPECT_NEAR(-matrix(fs, "T").at<double>(0), 540.0, 1e-6);
    EXPECT_NEAR(metadataOf(*src->grab())["focal_length_px"].as<double>(), 700.0, 1e-9);
    EXPECT_NEAR(metadataOf(*src->grab())["focal_length_px"].as<double>(), 710.0, 1e-9);

    fs::remove(kitti / "image_3" / "000001_10.png");
    std::string e = openError("{folder: " + kitti.string() + "}");
    EXPECT_NE(e.find(q(kitti / "image_3" / "000001_10.png")), std::string::npos) << e;
}

// ---- recording layout ------------------------------------------------------------------------

// A recording of `n` frames, images in left/ and right/, time stamps 1e9 + 50 ms * i.
void writeRecording(const fs::path &folder, int n, const std::string &tail = "") {
    std::string csv = "sequence,timestamp_left_ns,timestamp_right_ns,left,right\n";
    for (int i = 0; i < n; ++i) {
        const std::string name = "000" + std::to_string(i) + ".png";
        write(folder / "left" / name, noise({10, 6}, CV_8UC1, i));
        write(folder / "right" / name, noise({10, 6}, CV_8UC1, 100 + i));
        const int64_t t = 1000000000LL + 50000000LL * i;
        csv += std::to_string(i + 5) + "," + std::to_string(t) + "," + std::to_string(t + 1200) + ",left/" + name +
               ",right/" + name + "\n";
    }
    writeText(folder / "frames.csv", csv + tail);
    writeText(folder / "calibration.yml", binocle::StereoCalibration::ideal({10, 6}, 50.0, 75.0).toYaml());
    writeText(folder / "rig.yaml", "name: test rig\n");
}

void expectRecordedFrames(Source &src, int n) {
    for (int i = 0; i < n; ++i) {
        auto f = src.grab();
        ASSERT_TRUE(f) << "frame " << i;
        EXPECT_EQ(f->raw().sequence, static_cast<uint64_t>(i));
        EXPECT_EQ(f->raw().timestamp_left_ns, 1000000000LL + 50000000LL * i);
        EXPECT_EQ(f->raw().timestamp_right_ns, 1000000000LL + 50000000LL * i + 1200);
        EXPECT_EQ(f->raw().left.format, BINOCLE_PIXEL_GRAY8) << "grey files with color: gray";
        EXPECT_TRUE(equal(f->left(), noise({10, 6}, CV_8UC1, i)));
        EXPECT_TRUE(equal(f->right(), noise({10, 6}, CV_8UC1, 100 + i)));
        EXPECT_EQ(metadataOf(*f)["recorded_sequence"].as<int>(), i + 5);
    }
    EXPECT_EQ(src.grab(), nullptr);
}

TEST_F(Replay, RecordingPlaysItsFramesTimeStampsAndCalibration) {
    writeRecording(path("rec"), 4);
    auto src = open("{folder: " + path("rec").string() + ", color: gray}");
    expectRecordedFrames(*src, 4);
    std::ifstream in(path("rec/calibration.yml"));
    EXPECT_EQ(src->calibration(), std::string(std::istreambuf_iterator<char>(in), {})); // verbatim
}

TEST_F(Replay, RecordingCutShortIsReadableUpToItsLastCompleteFrame) {
    // The recorder stopped in the middle of a line.
    writeRecording(path("cut_line"), 4, "4,1200000000,12000");
    auto a = open("{folder: " + path("cut_line").string() + ", color: gray}");
    expectRecordedFrames(*a, 4);
    EXPECT_EQ(YAML::Load(a->statistics())["frames_dropped_at_end"].as<int>(), 1);

    // ... or after the line, before the images.
    writeRecording(path("cut_images"), 3, "8,1150000000,1150001200,left/0003.png,right/0003.png\n");
    auto b = open("{folder: " + path("cut_images").string() + ", color: gray}");
    expectRecordedFrames(*b, 3);

    // ... or while writing the last image.
    writeRecording(path("cut_png"), 4);
    const std::string png = path("cut_png/right/0003.png").string();
    fs::resize_file(png, fs::file_size(png) / 2);
    auto c = open("{folder: " + path("cut_png").string() + ", color: gray}");
    expectRecordedFrames(*c, 3);

    // A last line without its newline but complete is a frame.
    writeRecording(path("no_newline"), 2, "7,1100000000,1100001200,left/0002.png,right/0002.png");
    write(path("no_newline/left/0002.png"), noise({10, 6}, CV_8UC1, 2));
    write(path("no_newline/right/0002.png"), noise({10, 6}, CV_8UC1, 102));
    auto d = open("{folder: " + path("no_newline").string() + ", color: gray}");
    expectRecordedFrames(*d, 3);
}

TEST_F(Replay, RecordingLoopKeepsTimeStampsIncreasing) {
    writeRecording(path("rec"), 3);
    auto src = open("{folder: " + path("rec").string() + ", loop: true}");
    int64_t last = -1;
    for (int i = 0; i < 7; ++i) {
        auto f = src->grab();
        ASSERT_TRUE(f);
        EXPECT_GT(f->raw().timestamp_left_ns, last) << "grab " << i;
        last = f->raw().timestamp_left_ns;
    }
    EXPECT_EQ(last, 1000000000LL + 2 * 150000000LL + 50000000LL * 0); // third pass, first frame
}

TEST_F(Replay, RecordingErrorsNameFileAndLine) {
    writeRecording(path("gap"), 4);
    fs::remove(path("gap/left/0001.png"));
    std::string e = openError("{folder: " + path("gap").string() + "}");
    EXPECT_NE(e.find("frames.csv:3"), std::string::npos) << e;
    EXPECT_NE(e.find(q(path("gap/left/0001.png"))), std::string::npos) << e;

    writeRecording(path("garbled"), 3);
    writeText(path("garbled/frames.csv"), "sequence,timestamp_left_ns,timestamp_right_ns,left,right\n"
                                          "0,abc,1,left/0000.png,right/0000.png\n"
                                          "1,2,3,left/0001.png,right/0001.png\n");
    e = openError("{folder: " + path("garbled").string() + "}");
    EXPECT_NE(e.find("frames.csv:2"), std::string::npos) << e;

    writeRecording(path("header"), 1);
    writeText(path("header/frames.csv"), "seq,left,right\n0,left/0000.png,right/0000.png\n");
    e = openError("{folder: " + path("header").string() + "}");
    EXPECT_NE(e.find("timestamp_left_ns"), std::string::npos) << e;

    writeRecording(path("none"), 0, "0,1,2,left/0000.png,");
    e = openError("{layout: recording, folder: " + path("none").string() + "}");
    EXPECT_NE(e.find("no complete frame"), std::string::npos) << e;
}

// ---- Real data: OpenCV's Aloe pair with its ground truth ----------------------------------------

TEST_F(Replay, OpenCvAloePairWithGroundTruth) {
    const fs::path data = BINOCLE_OPENCV_DATA_DIR;
    if (!fs::exists(data / "aloeL.jpg")) GTEST_SKIP() << "opencv-doc examples not installed in " << data;
    // The 8-bit aloeGT.png holds disparities at this image size (1282x1110) directly.
    auto src = open("{left: " + (data / "aloeL.jpg").string() + ", right: " + (data / "aloeR.jpg").string() +
                    ", ground_truth: " + (data / "aloeGT.png").string() + "}");
    auto f = src->grab();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->left().size(), cv::Size(1282, 1110));
    EXPECT_EQ(f->left().type(), CV_8UC3);
    cv::Mat gt = f->extra("gt_disparity"), valid = f->extra("gt_valid");
    ASSERT_EQ(gt.size(), f->left().size());
    EXPECT_GT(cv::countNonZero(valid), gt.size().area() * 3 / 4);

    // The ground truth is right: the left pixel at (u, v) is the right pixel at (u - d, v).
    cv::Mat left, right;
    cv::cvtColor(f->left(), left, cv::COLOR_BGR2GRAY);
    cv::cvtColor(f->right(), right, cv::COLOR_BGR2GRAY);
    auto meanError = [&](double scale) {
        double sum = 0;
        int count = 0;
        for (int v = 0; v < gt.rows; v += 3)
            for (int u = 0; u < gt.cols; u += 3) {
                if (!valid.at<uint8_t>(v, u)) continue;
                const int ur = static_cast<int>(std::lround(u - scale * gt.at<float>(v, u)));
                if (ur < 0) continue;
                sum += std::abs(left.at<uint8_t>(v, u) - right.at<uint8_t>(v, ur));
                ++count;
            }
        return sum / std::max(count, 1);
    };
    const double matched = meanError(1.0);
    EXPECT_LT(matched, 12.0);
    EXPECT_LT(matched, 0.5 * meanError(0.0));
    EXPECT_LT(matched, meanError(0.5));
    EXPECT_EQ(src->grab(), nullptr);
}

} // namespace
