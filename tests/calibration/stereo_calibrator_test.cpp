// SPDX-License-Identifier: MIT
// Stereo calibration on opencv-doc's 13 real chessboard pairs, and the screening of poor
// pairs (flipped corner order, small board, outliers dropped after a first calibration).
#include "calibration/pair_folder.hpp"
#include "calibration/stereo_calibrator.hpp"
#include "core/error.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <iostream>

using namespace binocle;

namespace {

CalibrationOptions options9x6() {
    CalibrationOptions o;
    o.board = BoardSpec::parse("9x6", 25);
    return o;
}

// The 13 opencv-doc pairs, screened once for every test of this file.
const StereoCalibrator &openCvDocPairs() {
    static const StereoCalibrator calibrator = [] {
        StereoCalibrator c(options9x6());
        for (const auto &p : listImagePairs(BINOCLE_OPENCV_DATA_DIR).pairs)
            c.addPair(p.id, cv::imread(p.left, cv::IMREAD_GRAYSCALE), cv::imread(p.right, cv::IMREAD_GRAYSCALE), p.left, p.right);
        return c;
    }();
    return calibrator;
}

TEST(StereoCalibrator, OpenCvDocPairsCalibrateBelowOnePixel) {
    const StereoCalibrator &screened = openCvDocPairs();
    ASSERT_EQ(screened.pairs().size(), 13u);
    for (const auto &p : screened.pairs()) EXPECT_TRUE(p.used) << p.id << ": " << p.rejection;
    const CalibrationResult r = screened.calibrate();
    const StereoCalibration &c = r.calibration;
    std::cout << "opencv-doc: RMS " << r.rms_px << " px over " << r.usedPairs() << " pairs in " << r.rounds
              << " round(s); single-camera " << r.rms_left_px << " / " << r.rms_right_px << " px; baseline "
              << c.baselineMm() << " mm (25 mm squares); fx " << c.M1.at<double>(0, 0) << " / " << c.M2.at<double>(0, 0)
              << " px\n";
    for (const auto &p : r.pairs) std::cout << "  pair " << p.id << ": " << p.errorPx() << " px " << p.rejection << "\n";
    // Measured (OpenCV 4.6): RMS 0.316 px over all 13 pairs in one round (single-camera
    // 0.245 / 0.355 px); baseline 83.25 mm with 25 mm squares (3.33 squares); fx 534.4 /
    // 538.0 px. Per pair 0.16 (pair 11) to 0.53 px (pair 02).
    EXPECT_LT(r.rms_px, 1.0);
    EXPECT_EQ(r.usedPairs(), 13);
    EXPECT_EQ(c.image_size, cv::Size(640, 480));
    EXPECT_LT(c.T.at<double>(0), 0.0); // right camera to the right of the left one
    // The baseline scales with the square size: about 3.3 squares for this head.
    EXPECT_NEAR(c.baselineMm() / 25.0, 3.33, 0.15);
    EXPECT_NEAR(c.M1.at<double>(0, 0), c.M2.at<double>(0, 0), 0.02 * c.M1.at<double>(0, 0));
    EXPECT_FALSE(c.R1.empty());
    EXPECT_DOUBLE_EQ(c.rms_px, r.rms_px);

    // The report carries the figures and every pair.
    const std::string json = calibrationReport(r, options9x6(), 0).dump();
    EXPECT_NE(json.find("\"rms_px\""), std::string::npos);
    EXPECT_NE(json.find("\"baseline_mm\""), std::string::npos);
    EXPECT_NE(json.find("\"error_px\""), std::string::npos);
    EXPECT_EQ(json.find("\"focal_length_mm\""), std::string::npos); // no pixel pitch: no mm
    EXPECT_NE(calibrationReport(r, options9x6(), 6.0).dump().find("\"focal_length_mm\""), std::string::npos);
}

TEST(StereoCalibrator, FlippedCornerOrderIsRejected) {
    StereoCalibrator c(options9x6());
    const PairRecord &good = openCvDocPairs().pairs().front();
    BoardView right = good.right;
    std::reverse(right.corners.begin(), right.corners.end()); // the detector started from the other end
    const PairRecord &p = c.addViews("01", cv::Size(640, 480), good.left, right);
    EXPECT_FALSE(p.used);
    EXPECT_NE(p.rejection.find("corner ordering flipped between left and right"), std::string::npos) << p.rejection;
}

TEST(StereoCalibrator, PoorPairsAreRejectedWithTheReason) {
    CalibrationOptions o = options9x6();
    o.min_board_area_percent = 50; // every opencv-doc board is smaller than half the image
    StereoCalibrator small(o);
    const PairRecord &good = openCvDocPairs().pairs().front();
    EXPECT_NE(small.addViews("01", cv::Size(640, 480), good.left, good.right).rejection.find("board too small in the image"),
              std::string::npos);
    // Out of focus: the board is still found, but its edges are wide.
    StereoCalibrator sharp(options9x6());
    cv::Mat blurredLeft, blurredRight;
    cv::GaussianBlur(cv::imread(BINOCLE_OPENCV_DATA_DIR "/left03.jpg", 0), blurredLeft, cv::Size(0, 0), 2.5);
    cv::GaussianBlur(cv::imread(BINOCLE_OPENCV_DATA_DIR "/right03.jpg", 0), blurredRight, cv::Size(0, 0), 2.5);
    const PairRecord &blurred = sharp.addPair("03", blurredLeft, blurredRight);
    ASSERT_TRUE(blurred.left.found && blurred.right.found);
    EXPECT_NE(blurred.rejection.find("blurred: the board's edges are"), std::string::npos) << blurred.rejection;

    StereoCalibrator c(options9x6());
    EXPECT_NE(c.addPair("x", cv::Mat(480, 640, CV_8U, cv::Scalar(90)), cv::imread(BINOCLE_OPENCV_DATA_DIR "/right01.jpg", 0))
                  .rejection.find("not found in the left image"),
              std::string::npos);
    EXPECT_NE(c.addPair("y", cv::imread(BINOCLE_OPENCV_DATA_DIR "/left01.jpg", 0), cv::Mat(480, 640, CV_8U, cv::Scalar(90)))
                  .rejection.find("not found in the right image"),
              std::string::npos);
    EXPECT_NE(c.addPair("z", cv::Mat(480, 640, CV_8U), cv::Mat(240, 320, CV_8U)).rejection.find("left image is 640x480 but right image is 320x240"),
              std::string::npos);
    // Too few usable pairs: no calibration, and the error says why.
    try {
        c.calibrate();
        FAIL() << "calibrated from no usable pair";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("only 0 usable pair(s) out of 3"), std::string::npos) << e.what();
    }
}

TEST(StereoCalibrator, AnOutlierPairIsDroppedAndTheRestRecalibrated) {
    StereoCalibrator c(options9x6());
    int k = 0;
    for (const auto &p : openCvDocPairs().pairs()) {
        BoardView right = p.right;
        if (k++ == 4) // one pair with its right corners shifted unevenly, as a bad detection would
            for (size_t i = 0; i < right.corners.size(); ++i) right.corners[i].y += static_cast<float>(i % 9) * 0.8f;
        c.addViews(p.id, cv::Size(640, 480), p.left, right, p.left_name, p.right_name);
    }
    const CalibrationResult r = c.calibrate();
    EXPECT_EQ(r.usedPairs(), 12);
    EXPECT_GE(r.rounds, 2);
    EXPECT_LT(r.rms_px, 1.0);
    const PairRecord &dropped = r.pairs[4];
    EXPECT_FALSE(dropped.used);
    EXPECT_NE(dropped.rejection.find("reprojection error"), std::string::npos) << dropped.rejection;
    EXPECT_NE(dropped.rejection.find("dropped and recalibrated"), std::string::npos) << dropped.rejection;
}

} // namespace
