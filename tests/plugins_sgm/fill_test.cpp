// SPDX-License-Identifier: MIT
// sgm's dense option (sgm_fill.hpp): occlusions filled from the background side,
// mismatches from all sides, on maps built by hand; and the engine with it: only the
// pixels the checks left invalid change, every one of them is marked, and the matched
// ones keep their values.
#include "sgm_engine.hpp"
#include "sgm_fill.hpp"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace {

constexpr float kInvalid = -1.0f;

// A map of `left` on columns < x0, `right` on columns >= x1, invalid between: a vertical
// strip of holes through every row.
cv::Mat strip(cv::Size size, int x0, int x1, float left, float right) {
    cv::Mat d(size, CV_32FC1, cv::Scalar(kInvalid));
    d.colRange(0, x0).setTo(cv::Scalar(left));
    d.colRange(x1, size.width).setTo(cv::Scalar(right));
    return d;
}

// Every pixel of the strip is filled and marked, the rest unchanged and unmarked.
void expectOnlyTheStripFilled(const cv::Mat &before, const cv::Mat &after, const cv::Mat &filled, int x0, int x1) {
    ASSERT_EQ(filled.type(), CV_8UC1);
    ASSERT_EQ(filled.size(), before.size());
    EXPECT_EQ(cv::countNonZero(filled.colRange(x0, x1) != 255), 0);
    EXPECT_EQ(cv::countNonZero(filled.colRange(0, x0)), 0);
    EXPECT_EQ(cv::countNonZero(filled.colRange(x1, before.cols)), 0);
    EXPECT_EQ(cv::countNonZero(after.colRange(0, x0) != before.colRange(0, x0)), 0);
    EXPECT_EQ(cv::countNonZero(after.colRange(x1, before.cols) != before.colRange(x1, before.cols)), 0);
    EXPECT_EQ(cv::countNonZero(after == kInvalid), 0);
}

// Background (10 px) left of a foreground (30 px): the holes between are occluded in the
// right image and take the background's disparity, never the occluder's.
TEST(SgmFill, FillsAnOcclusionFromTheBackground) {
    const cv::Mat before = strip({60, 40}, 20, 30, 10.0f, 30.0f);
    cv::Mat d = before.clone(), filled;
    sgm::Filler f;
    f.fill(d, kInvalid, 1.0f, filled);
    expectOnlyTheStripFilled(before, d, filled, 20, 30);
    EXPECT_EQ(cv::countNonZero(d.colRange(20, 30) != 10.0f), 0);
}

// Foreground (30 px) left of a background (10 px): nothing there is occluded in the right
// image, so the holes are mismatches: the median of the 8 directions' values. In a middle
// row left, up-left and down-left bring 30, right, up-right and down-right 10: the median
// of six values is the mean of the two middle ones, 20.
TEST(SgmFill, FillsAMismatchFromAllSides) {
    const cv::Mat before = strip({60, 40}, 20, 30, 30.0f, 10.0f);
    cv::Mat d = before.clone(), filled;
    sgm::Filler f;
    f.fill(d, kInvalid, 1.0f, filled);
    expectOnlyTheStripFilled(before, d, filled, 20, 30);
    EXPECT_EQ(d.at<float>(20, 25), 20.0f);
    // The same map, with a step of 20 px called no occlusion: the median too.
    cv::Mat occluded = strip({60, 40}, 20, 30, 10.0f, 30.0f), marks;
    f.fill(occluded, kInvalid, 25.0f, marks);
    EXPECT_EQ(occluded.at<float>(20, 25), 20.0f);
}

// A small hole in a slanted plane (a mismatch: the step across it is under 1 px) is
// filled close to the plane; a run that touches the left border (columns whose match
// would lie left of the right image) takes the row's value on its right.
TEST(SgmFill, FillsHolesInAPlaneAndAtTheLeftBorder) {
    cv::Mat d(50, 80, CV_32FC1);
    for (int y = 0; y < d.rows; ++y)
        for (int x = 0; x < d.cols; ++x) d.at<float>(y, x) = 20.0f + 0.1f * x + 0.05f * y;
    const cv::Mat plane = d.clone();
    d(cv::Rect(40, 20, 3, 3)).setTo(cv::Scalar(kInvalid));
    d(cv::Rect(0, 30, 4, 1)).setTo(cv::Scalar(kInvalid));
    cv::Mat filled;
    sgm::Filler f;
    f.fill(d, kInvalid, 1.0f, filled);
    EXPECT_EQ(cv::countNonZero(filled), 9 + 4);
    cv::Mat error;
    cv::absdiff(d(cv::Rect(40, 20, 3, 3)), plane(cv::Rect(40, 20, 3, 3)), error);
    double worst = 0;
    cv::minMaxLoc(error, nullptr, &worst);
    EXPECT_LT(worst, 0.25);
    // At the border: the row's valid value on the right of the run.
    for (int x = 0; x < 4; ++x) EXPECT_EQ(d.at<float>(30, x), plane.at<float>(30, 4)) << x;
}

// With no valid pixel in any direction a hole stays one, unmarked; a map without holes
// is left as it is.
TEST(SgmFill, LeavesWhatNothingReaches) {
    cv::Mat none(8, 9, CV_32FC1, cv::Scalar(kInvalid)), filled;
    sgm::Filler f;
    f.fill(none, kInvalid, 1.0f, filled);
    EXPECT_EQ(cv::countNonZero(none != kInvalid), 0);
    EXPECT_EQ(cv::countNonZero(filled), 0);
    cv::Mat full(8, 9, CV_32FC1, cv::Scalar(7.5)), marks;
    f.fill(full, kInvalid, 1.0f, marks);
    EXPECT_EQ(cv::countNonZero(full != 7.5f), 0);
    EXPECT_EQ(cv::countNonZero(marks), 0);
}

// The engine with fillDense: the matched pixels keep their values, exactly those the
// checks left invalid are filled and marked, and nothing stays invalid (the same with
// every stripe count: the fill runs over the whole image).
TEST(SgmFill, EngineFillsOnlyWhatTheChecksRemoved) {
    cv::Mat back(90, 130, CV_8UC1), front(90, 130, CV_8UC1);
    cv::RNG rng(7);
    rng.fill(back, cv::RNG::UNIFORM, 0, 256);
    rng.fill(front, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(back, back, cv::Size(3, 3), 0.8);
    cv::GaussianBlur(front, front, cv::Size(3, 3), 0.8);
    // A background at 6 px and a square at 16 px in front of it (left image columns 60 ..
    // 99, rows 30 .. 69): the background just left of the square is occluded.
    cv::Mat left(90, 120, CV_8UC1), right(90, 120, CV_8UC1);
    for (int y = 0; y < 90; ++y)
        for (int x = 0; x < 120; ++x) {
            const bool rows = y >= 30 && y < 70;
            left.at<uint8_t>(y, x) = rows && x >= 60 && x < 100 ? front.at<uint8_t>(y, x) : back.at<uint8_t>(y, x + 6);
            right.at<uint8_t>(y, x) = rows && x + 16 >= 60 && x + 16 < 100 ? front.at<uint8_t>(y, x + 16)
                                                                          : back.at<uint8_t>(y, x + 12);
        }
    for (int stripes : {1, 3}) {
        sgm::Settings s;
        s.numDisparities = 32;
        s.stripes = stripes;
        sgm::Engine sparse(s, sgm::bestKernels());
        s.fillDense = true;
        sgm::Engine dense(s, sgm::bestKernels());
        cv::Mat a(left.size(), CV_32FC1), b(left.size(), CV_32FC1);
        sparse.compute(left, right, a, kInvalid);
        dense.compute(left, right, b, kInvalid);
        EXPECT_TRUE(sparse.filled().empty());
        const cv::Mat holes = a == kInvalid;
        ASSERT_GT(cv::countNonZero(holes), 0) << "the pair leaves no hole to fill";
        EXPECT_EQ(cv::countNonZero(dense.filled() != holes), 0) << stripes;
        EXPECT_EQ(cv::countNonZero(b == kInvalid), 0) << stripes;
        cv::Mat changed = a != b;
        EXPECT_EQ(cv::countNonZero(changed & ~holes), 0) << stripes;
    }
}

} // namespace
