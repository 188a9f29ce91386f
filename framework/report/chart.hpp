// SPDX-License-Identifier: MIT
// Charts people can look at: grouped bar charts (the paper's Fig. 6 and 7) and scatter
// plots, rendered to SVG text and to a PNG image from the same description.
#pragma once

#include <opencv2/core.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace binocle {

struct BarGroup {
    std::string label;          // e.g. "R = 6 m, B = 100 mm"
    std::vector<double> values; // one per series; NaN = missing (drawn as "n/a")
    // Error bars (e.g. the 95 % confidence interval of repeats): low and high end per
    // series; empty, or NaN for one series: no bar.
    std::vector<double> low, high;
    // A reference value per series drawn as a black diamond (e.g. the paper's figure); NaN: none.
    std::vector<double> reference;
};

struct BarChart {
    std::string title;
    std::string y_label;                // e.g. "stereo efficiency η3D (%)"
    std::vector<std::string> series;    // e.g. lens names "f = 2.8 mm"
    std::vector<BarGroup> groups;
    double y_min = 0, y_max = 100;
    std::vector<double> reference_lines; // horizontal dashed lines (e.g. 70 %)
    std::string reference_label;         // legend entry of BarGroup::reference ("paper")
};

struct ScatterPoint {
    double x = 0, y = 0;
    std::string label; // drawn beside the point (e.g. test number)
    int series = 0;
    double y_low = NAN, y_high = NAN; // vertical error bar; NaN: none
};

struct ScatterChart {
    std::string title, x_label, y_label;
    std::vector<std::string> series;
    std::vector<ScatterPoint> points;
    double x_min = 0, x_max = 0, y_min = 0, y_max = 0; // max <= min: from the data
    // Vertical band highlighted on the x axis (the paper's good FF range 1.2-2.0).
    double band_min = 0, band_max = 0;
};

std::string toSvg(const BarChart &chart, int width = 960, int height = 540);
cv::Mat toImage(const BarChart &chart, int width = 960, int height = 540);
std::string toSvg(const ScatterChart &chart, int width = 800, int height = 560);
cv::Mat toImage(const ScatterChart &chart, int width = 800, int height = 560);

// Writes <stem>.png and <stem>.svg, atomically.
void writeChart(const std::string &stem, const BarChart &chart);
void writeChart(const std::string &stem, const ScatterChart &chart);

} // namespace binocle
