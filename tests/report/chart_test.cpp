// SPDX-License-Identifier: MIT
// Charts: the same description gives an SVG and a PNG that show the data.
#include "common/test_util.hpp"
#include "report/chart.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

using namespace binocle;

namespace {

BarChart sample() {
    BarChart c;
    c.title = "E1: stereo efficiency η3D per test";
    c.y_label = "η3D (%)";
    c.series = {"f = 2.8 mm", "f = 4 mm", "f = 8 mm", "f = 12 mm"};
    c.groups = {{"R = 6 m, B = 100 mm", {40, 60, 82, 50}}, {"R = 6 m, B = 150 mm", {71, 74, 78, NAN}}};
    c.reference_lines = {70};
    return c;
}

TEST(Chart, BarChartSvgHasOneBarPerValueAndMarksMissingOnes) {
    const std::string svg = toSvg(sample());
    size_t rects = 0;
    for (size_t p = svg.find("<rect"); p != std::string::npos; p = svg.find("<rect", p + 1)) ++rects;
    // background + 7 bars + 4 legend swatches
    EXPECT_EQ(rects, 1u + 7u + 4u);
    EXPECT_NE(svg.find("n/a"), std::string::npos);
    EXPECT_NE(svg.find("η3D (%)"), std::string::npos);
    EXPECT_NE(svg.find("stroke-dasharray"), std::string::npos); // the 70 % reference line
}

TEST(Chart, BarChartImageIsDrawnAndTallerBarsAreTaller) {
    BarChart c;
    c.series = {"a"};
    c.groups = {{"low", {20}}, {"high", {80}}};
    cv::Mat img = toImage(c, 400, 300);
    ASSERT_EQ(img.size(), cv::Size(400, 300));
    // Count coloured (non-grey) pixels per half: the bar of 80 covers more than the bar of 20.
    auto coloured = [&](int x0, int x1) {
        int n = 0;
        for (int y = 0; y < img.rows; ++y)
            for (int x = x0; x < x1; ++x) {
                const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
                if (std::abs(p[0] - p[2]) > 60) ++n;
            }
        return n;
    };
    const int mid = 70 + (400 - 20 - 150 - 70) / 2;
    EXPECT_GT(coloured(mid, 400 - 170), 3 * coloured(70, mid));
}

TEST(Chart, ScatterWritesPngAndSvg) {
    ScatterChart s;
    s.title = "η3D against FF";
    s.x_label = "form factor FF";
    s.y_label = "η3D (%)";
    s.band_min = 1.2;
    s.band_max = 2.0;
    s.points = {{0.47, 40, "1"}, {1.5, 85, "3"}, {3.0, 50, "8"}};
    test::TempDir dir;
    writeChart(dir.str("ff"), s);
    cv::Mat png = cv::imread(dir.str("ff.png"));
    ASSERT_FALSE(png.empty());
    EXPECT_EQ(png.cols, 800);
    const std::string svg = test::runCommand("cat " + dir.str("ff.svg")).output;
    size_t circles = 0;
    for (size_t p = svg.find("<circle"); p != std::string::npos; p = svg.find("<circle", p + 1)) ++circles;
    EXPECT_EQ(circles, 3u);
}

} // namespace

namespace {

size_t count(const std::string &text, const std::string &what) {
    size_t n = 0;
    for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
    return n;
}

TEST(Chart, ErrorBarsAndReferenceMarksAreDrawnWhereGiven) {
    BarChart c = sample();
    const size_t plainLines = count(toSvg(c), "<line");
    // Two whiskers (3 lines each: bar and two caps) and one paper diamond (4 lines + 4 in the legend).
    c.groups[0].low = {35, NAN, 78, NAN};
    c.groups[0].high = {45, NAN, 86, NAN};
    c.groups[1].reference = {NAN, NAN, 78, NAN};
    c.reference_label = "paper";
    const std::string svg = toSvg(c);
    EXPECT_EQ(count(svg, "<line"), plainLines + 2 * 3 + 4 + 4);
    EXPECT_NE(svg.find(">paper<"), std::string::npos);

    ScatterChart s;
    s.points = {{1.0, 80, "1", 0}, {2.0, 60, "2", 0}};
    const size_t scatterLines = count(toSvg(s), "<line");
    s.points[0].y_low = 75;
    s.points[0].y_high = 85;
    EXPECT_EQ(count(toSvg(s), "<line"), scatterLines + 3);
    EXPECT_FALSE(toImage(s).empty());
}

} // namespace
