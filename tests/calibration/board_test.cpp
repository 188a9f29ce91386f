// SPDX-License-Identifier: MIT
// The chessboard: --board parsing, detection with sub-pixel corners, pair folders, stillness.
#include "calibration/board.hpp"
#include "calibration/pair_folder.hpp"
#include "calibration/still_board.hpp"
#include "common/test_util.hpp"
#include "core/error.hpp"

#include <functional>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

using namespace binocle;
using binocle::test::TempDir;
using binocle::test::writeText;
namespace fs = std::filesystem;

namespace {

std::string errorOf(const std::function<void()> &f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    }
    return "";
}

TEST(Board, ParsesColsByRows) {
    const BoardSpec b = BoardSpec::parse("9x6", 25);
    EXPECT_EQ(b.cols, 9);
    EXPECT_EQ(b.rows, 6);
    EXPECT_EQ(b.square_mm, 25);
    EXPECT_EQ(BoardSpec::parse("7X5", 30).patternSize(), cv::Size(7, 5));
    const auto points = b.objectPoints();
    ASSERT_EQ(points.size(), 54u);
    EXPECT_EQ(points[1], cv::Point3f(25, 0, 0));
    EXPECT_EQ(points[9], cv::Point3f(0, 25, 0));
}

TEST(Board, MalformedBoardsAreRefusedWithTheValue) {
    EXPECT_NE(errorOf([] { BoardSpec::parse("9by6", 25); }).find("--board '9by6': expected COLSxROWS"), std::string::npos);
    EXPECT_NE(errorOf([] { BoardSpec::parse("1x6", 25); }).find("at least 2x2"), std::string::npos);
    EXPECT_NE(errorOf([] { BoardSpec::parse("7x7", 25); }).find("no distinct orientation"), std::string::npos);
    EXPECT_NE(errorOf([] { BoardSpec::parse("9x6", 0); }).find("--square-mm"), std::string::npos);
    EXPECT_NE(errorOf([] { BoardSpec::parse("9x6", -3); }).find("--square-mm -3: expected"), std::string::npos);
    // The counts go through the one number reader: no leading zero, space or extra part.
    EXPECT_NE(errorOf([] { BoardSpec::parse("09x6", 25); }).find("'09' is not valid: expected a decimal integer without leading zeros"),
              std::string::npos);
    EXPECT_NE(errorOf([] { BoardSpec::parse("9x6x2", 25); }).find("'6x2' is not valid"), std::string::npos);
    EXPECT_NE(errorOf([] { BoardSpec::parse("9x1000", 25); }).find("'1000' is not valid"), std::string::npos);
}

TEST(Board, FindsTheOpenCvDocBoardWithSubPixelCorners) {
    const BoardSpec b = BoardSpec::parse("9x6", 25);
    const cv::Mat image = cv::imread(BINOCLE_OPENCV_DATA_DIR "/left01.jpg", cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty());
    const BoardView v = findBoard(image, b);
    ASSERT_TRUE(v.found);
    EXPECT_EQ(v.corners.size(), 54u);
    EXPECT_GT(v.area_percent, 5.0);
    EXPECT_GT(v.edge_width_px, 0.0);
    EXPECT_LT(v.edge_width_px, 4.0);
    // Sub-pixel: not all corners on integer positions.
    int fractional = 0;
    for (const auto &p : v.corners) fractional += (p.x != std::round(p.x)) ? 1 : 0;
    EXPECT_GT(fractional, 40);

    // A blurred copy: same corners within a pixel, wider edges.
    cv::Mat blurred;
    cv::GaussianBlur(image, blurred, cv::Size(0, 0), 4.0);
    const BoardView vb = findBoard(blurred, b);
    if (vb.found) {
        EXPECT_GT(vb.edge_width_px, v.edge_width_px + 2.0);
        EXPECT_LT(meanCornerShiftPx(v.corners, vb.corners), 1.0);
    }
    // Wrong pattern size: not found.
    EXPECT_FALSE(findBoard(image, BoardSpec::parse("8x5", 25)).found);
    EXPECT_FALSE(findBoard(cv::Mat(480, 640, CV_8U, cv::Scalar(128)), b).found);
}

TEST(PairFolder, MatchesLeftAndRightByNumber) {
    TempDir dir;
    for (const char *f : {"left01.jpg", "right01.jpg", "left2.png", "right02.png", "left03.jpg", "right04.jpg", "left.jpg",
                          "notes.txt", "right_intrinsics.yml", "other05.png"})
        writeText(dir.str(f), "x");
    const PairListing l = listImagePairs(dir.str());
    ASSERT_EQ(l.pairs.size(), 2u);
    EXPECT_EQ(l.pairs[0].id, "01");
    EXPECT_EQ(l.pairs[1].id, "2");
    EXPECT_EQ(fs::path(l.pairs[1].right).filename(), "right02.png");
    std::string unmatched;
    for (const auto &u : l.unmatched) unmatched += u + "\n";
    EXPECT_NE(unmatched.find("left03.jpg: no right image numbered 03"), std::string::npos) << unmatched;
    EXPECT_NE(unmatched.find("right04.jpg: no left image numbered 04"), std::string::npos) << unmatched;
    EXPECT_NE(unmatched.find("left.jpg: no number"), std::string::npos) << unmatched;
    EXPECT_NE(errorOf([] { listImagePairs("/nonexistent/pairs"); }).find("--pairs /nonexistent/pairs: not a folder"),
              std::string::npos);
}

TEST(PairFolder, OpenCvDocHasThirteenPairs) {
    const PairListing l = listImagePairs(BINOCLE_OPENCV_DATA_DIR);
    EXPECT_EQ(l.pairs.size(), 13u); // left01..left14 without 10
}

TEST(StillBoard, TakesAPairOnceTheBoardHasBeenStill) {
    BoardView a, moved;
    a.found = moved.found = true;
    for (int i = 0; i < 54; ++i) {
        a.corners.emplace_back(100.0f + 10 * (i % 9), 100.0f + 10 * (i / 9));
        moved.corners.emplace_back(160.0f + 10 * (i % 9), 130.0f + 10 * (i / 9));
    }
    BoardView jitter = a;
    for (auto &p : jitter.corners) p.x += 0.3f;
    BoardView none;
    StillBoard still(3, 1.0, 20.0);
    EXPECT_FALSE(still.update(a, a));
    EXPECT_FALSE(still.update(jitter, jitter));
    EXPECT_TRUE(still.update(a, a)); // third frame within 1 px
    EXPECT_FALSE(still.update(a, a)); // not again at the same place
    EXPECT_FALSE(still.update(a, a));
    EXPECT_FALSE(still.update(moved, moved));
    EXPECT_FALSE(still.update(none, moved)); // left lost the board: start again
    EXPECT_FALSE(still.update(moved, moved));
    EXPECT_FALSE(still.update(moved, moved));
    EXPECT_TRUE(still.update(moved, moved));
}

} // namespace
