// SPDX-License-Identifier: MIT
// Drawing density views: colour cells, axes in metres, titles, colour scale, overlays.
#include "method/density_render.hpp"

#include "files/atomic_file.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace binocle::method {

namespace {

const cv::Scalar kInk(30, 30, 30), kGrid(228, 228, 228), kPaper(255, 255, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

const char *axisTitle(View view, bool horizontal) {
    switch (view) {
    case View::Top: return horizontal ? "X lateral (m)" : "Y range (m)";
    case View::Front: return horizontal ? "X lateral (m)" : "Z height (m)";
    case View::Side: return horizontal ? "Y range (m)" : "Z height (m)";
    }
    return "";
}

std::string viewTitle(View view) {
    std::string name = viewName(view);
    name[0] = static_cast<char>(name[0] - 'a' + 'A');
    return name + " view (" + viewAxes(view) + ")";
}

// A tick step in mm giving ticks at least minPixels apart.
double tickStep(double mmPerPixel, int minPixels) {
    static const double steps[] = {100, 200, 250, 500, 1000, 2000, 2500, 5000, 10000, 20000, 50000, 100000};
    for (double s : steps)
        if (s / mmPerPixel >= minPixels) return s;
    return 200000;
}

std::string metres(double mm) {
    char buf[32];
    const double m = std::fabs(mm) < 1e-6 ? 0.0 : mm / 1000.0;
    if (std::fabs(m - std::round(m)) < 1e-6) std::snprintf(buf, sizeof buf, "%.0f", m);
    else if (std::fabs(m * 10 - std::round(m * 10)) < 1e-6) std::snprintf(buf, sizeof buf, "%.1f", m);
    else std::snprintf(buf, sizeof buf, "%.2f", m);
    return buf;
}

void text(cv::Mat &img, const std::string &s, cv::Point at, double scale, const cv::Scalar &color, int thickness = 1) {
    cv::putText(img, s, at, kFont, scale, color, thickness, cv::LINE_AA);
}

cv::Size textSize(const std::string &s, double scale, int thickness = 1) {
    int base = 0;
    return cv::getTextSize(s, kFont, scale, thickness, &base);
}

// Text written upwards (for the vertical axis), its centre at `centre`.
void verticalText(cv::Mat &img, const std::string &s, cv::Point centre, double scale) {
    const cv::Size sz = textSize(s, scale);
    cv::Mat strip(sz.height + 8, sz.width + 4, CV_8UC3, kPaper);
    text(strip, s, {2, sz.height + 2}, scale, kInk);
    cv::Mat up;
    cv::rotate(strip, up, cv::ROTATE_90_COUNTERCLOCKWISE);
    const cv::Rect r(centre.x - up.cols / 2, centre.y - up.rows / 2, up.cols, up.rows);
    const cv::Rect inside = r & cv::Rect(0, 0, img.cols, img.rows);
    if (inside.area() == r.area()) up.copyTo(img(r));
}

cv::Vec3b viridis(double t) { // t in [0, 1]
    static cv::Mat lut = [] {
        cv::Mat ramp(1, 256, CV_8U);
        for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(0, i) = static_cast<uint8_t>(i);
        cv::Mat colored;
        cv::applyColorMap(ramp, colored, cv::COLORMAP_VIRIDIS);
        return colored;
    }();
    const int i = std::clamp(static_cast<int>(std::lround(t * 255)), 0, 255);
    return lut.at<cv::Vec3b>(0, i);
}

cv::Vec3b pale(cv::Vec3b c) { return {uint8_t((c[0] + 2 * 255) / 3), uint8_t((c[1] + 2 * 255) / 3), uint8_t((c[2] + 2 * 255) / 3)}; }

// Where the view lands in the picture: square cells of whole pixels, margins for the
// axes (left, bottom), the title (top) and the colour scale (right).
struct PlotArea {
    int cell_px = 1, width_px = 0, height_px = 0; // a cell's side, the plot's size
    static constexpr int left = 78, right = 130, top = 56, bottom = 62;
    double mm_per_px = 1;
    double u_min_mm = 0, v_min_mm = 0; // the view's lower-left corner

    int px(double u_mm) const { return left + static_cast<int>(std::lround((u_mm - u_min_mm) / mm_per_px)); }
    int py(double v_mm) const { return top + height_px - static_cast<int>(std::lround((v_mm - v_min_mm) / mm_per_px)); }
};

PlotArea plotAreaOf(const DensityView &view, const RenderOptions &options) {
    PlotArea a;
    const int cols = std::max(1, view.cols()), rows = std::max(1, view.rows());
    a.cell_px = std::max(1, static_cast<int>(std::lround(static_cast<double>(options.target_size_px) / std::max(cols, rows))));
    while (a.cell_px > 1 && std::max(cols, rows) * a.cell_px > 1600) --a.cell_px;
    a.width_px = cols * a.cell_px;
    a.height_px = rows * a.cell_px;
    a.mm_per_px = view.cell_mm / a.cell_px;
    a.u_min_mm = view.u.min_mm;
    a.v_min_mm = view.v.min_mm;
    return a;
}

// The ticks of both axes: their steps and the first tick at or past each axis' start.
struct AxisTicks {
    double u_step_mm, v_step_mm, u0_mm, v0_mm;
};

AxisTicks axisTicksOf(const DensityView &view, const PlotArea &a) {
    const double uStep = tickStep(a.mm_per_px, 60), vStep = tickStep(a.mm_per_px, 45);
    return {uStep, vStep, std::ceil(view.u.min_mm / uStep) * uStep, std::ceil(view.v.min_mm / vStep) * vStep};
}

// Grid lines at the ticks, drawn first so that the cells cover them.
void drawGrid(cv::Mat &img, const DensityView &view, const PlotArea &a, const AxisTicks &t) {
    for (double u = t.u0_mm; u <= view.u.max_mm + 1e-6; u += t.u_step_mm)
        cv::line(img, {a.px(u), a.top}, {a.px(u), a.top + a.height_px}, kGrid, 1);
    for (double v = t.v0_mm; v <= view.v.max_mm + 1e-6; v += t.v_step_mm)
        cv::line(img, {a.left, a.py(v)}, {a.left + a.width_px, a.py(v)}, kGrid, 1);
}

// Cells: log scale so that sparse outliers and a dense panel are both visible.
void drawCells(cv::Mat &img, const DensityView &view, const PlotArea &a, int densityThreshold, double logMax) {
    for (int r = 0; r < view.rows(); ++r)
        for (int c = 0; c < view.cols(); ++c) {
            const int n = view.count(r, c);
            if (n <= 0) continue;
            cv::Vec3b color = viridis(std::log1p(static_cast<double>(n)) / logMax);
            if (n < densityThreshold) color = pale(color);
            const cv::Rect cell(a.left + c * a.cell_px, a.top + a.height_px - (r + 1) * a.cell_px, a.cell_px, a.cell_px);
            img(cell).setTo(cv::Scalar(color[0], color[1], color[2]));
        }
}

// The camera (the ground frame's origin) in the top view.
void drawCamera(cv::Mat &img, const DensityView &view, const PlotArea &a) {
    if (!(view.view == View::Top && view.u.contains(0) && view.v.min_mm <= 0)) return;
    const cv::Point c(a.px(0), std::min(a.py(0), a.top + a.height_px));
    std::vector<cv::Point> tri{{c.x, c.y - 12}, {c.x - 8, c.y}, {c.x + 8, c.y}};
    cv::fillConvexPoly(img, tri, cv::Scalar(60, 60, 230), cv::LINE_AA);
    text(img, "camera", {c.x + 10, c.y - 4}, 0.4, cv::Scalar(60, 60, 230));
}

void drawOverlay(cv::Mat &img, const PlotArea &a, const ViewOverlay &o) {
    const cv::Point from(a.px(o.u.min_mm), a.py(o.v.max_mm)), to(a.px(o.u.max_mm), a.py(o.v.min_mm));
    if (!o.cells.empty() && o.cell_mm > 0) {
        // The outline of the cells the reading took, over the counts it read them from.
        cv::Mat mask = cv::Mat::zeros(img.size(), CV_8U);
        for (const auto &c : o.cells)
            cv::rectangle(mask, cv::Point(a.px(c[0]), a.py(c[1] + o.cell_mm)), cv::Point(a.px(c[0] + o.cell_mm) - 1, a.py(c[1]) - 1),
                          255, cv::FILLED);
        mask(cv::Rect(0, 0, img.cols, a.top)).setTo(0);
        std::vector<std::vector<cv::Point>> contours;
        cv::findContours(mask, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
        cv::drawContours(img, contours, -1, o.color, 1, cv::LINE_8);
        cv::rectangle(img, from, to, o.color, 1, cv::LINE_AA);
    } else {
        cv::rectangle(img, from, to, o.color, 2, cv::LINE_AA);
    }
    if (!o.label.empty()) {
        const cv::Point at(std::clamp(from.x, a.left, a.left + a.width_px - 10), std::max(from.y - 5, a.top + 12));
        text(img, o.label, at, 0.42, o.color, 1);
    }
}

// The plot's frame, the ticks with their values in metres, and both axis titles.
void drawAxes(cv::Mat &img, const DensityView &view, const PlotArea &a, const AxisTicks &t) {
    const int left = a.left, top = a.top, W = a.width_px, H = a.height_px;
    cv::rectangle(img, {left, top}, {left + W, top + H}, kInk, 1);
    for (double u = t.u0_mm; u <= view.u.max_mm + 1e-6; u += t.u_step_mm) {
        const int x = a.px(u);
        cv::line(img, {x, top + H}, {x, top + H + 5}, kInk, 1);
        const std::string label = metres(u);
        text(img, label, {x - textSize(label, 0.42).width / 2, top + H + 20}, 0.42, kInk);
    }
    for (double v = t.v0_mm; v <= view.v.max_mm + 1e-6; v += t.v_step_mm) {
        const int y = a.py(v);
        cv::line(img, {left - 5, y}, {left, y}, kInk, 1);
        const std::string label = metres(v);
        const cv::Size sz = textSize(label, 0.42);
        text(img, label, {left - 9 - sz.width, y + sz.height / 2}, 0.42, kInk);
    }
    const std::string ut = axisTitle(view.view, true);
    text(img, ut, {left + W / 2 - textSize(ut, 0.5).width / 2, top + H + 48}, 0.5, kInk);
    verticalText(img, axisTitle(view.view, false), {18, top + H / 2}, 0.5);
}

void drawTitle(cv::Mat &img, const DensityView &view, const PlotArea &a, const std::string &given) {
    std::string title = given;
    if (title.empty()) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "%s - %lld points, cell %g mm", viewTitle(view.view).c_str(),
                      static_cast<long long>(view.total()), view.cell_mm);
        title = buf;
    }
    double titleScale = 0.6; // smaller for a narrow view, so that the title stays whole
    while (titleScale > 0.35 && a.left + textSize(title, titleScale).width > img.cols - 8) titleScale -= 0.05;
    text(img, title, {std::max(8, std::min(a.left, img.cols - 8 - textSize(title, titleScale).width)), 34}, titleScale, kInk, 1);
}

// Colour scale: log(1 + count) from 1 to the largest count, with the threshold.
void drawColourScale(cv::Mat &img, const PlotArea &a, int maxCount, double logMax, int densityThreshold) {
    const int barX = a.left + a.width_px + 28, barW = 16, barH = std::min(a.height_px, 320), barY = a.top;
    for (int y = 0; y < barH; ++y) {
        const double t = 1.0 - static_cast<double>(y) / std::max(1, barH - 1);
        const double n = std::expm1(t * logMax);
        cv::Vec3b color = viridis(t);
        if (n < densityThreshold) color = pale(color);
        cv::line(img, {barX, barY + y}, {barX + barW, barY + y}, cv::Scalar(color[0], color[1], color[2]), 1);
    }
    cv::rectangle(img, {barX, barY}, {barX + barW, barY + barH}, kInk, 1);
    auto barMark = [&](int n, const std::string &label) {
        const double t = std::log1p(static_cast<double>(n)) / logMax;
        const int y = barY + static_cast<int>(std::lround((1.0 - t) * (barH - 1)));
        cv::line(img, {barX + barW, y}, {barX + barW + 4, y}, kInk, 1);
        text(img, label, {barX + barW + 7, y + 4}, 0.38, kInk);
    };
    std::vector<int> marks{1, maxCount};
    for (int decade = 10; decade < maxCount; decade *= 10)
        if (decade * 2 < maxCount) marks.push_back(decade);
    for (int n : marks)
        if (n <= maxCount) barMark(n, std::to_string(n));
    if (densityThreshold > 1 && densityThreshold < maxCount)
        barMark(densityThreshold, "thr " + std::to_string(densityThreshold));
    text(img, "points", {barX - 6, barY + barH + 20}, 0.4, kInk);
    text(img, "per cell", {barX - 6, barY + barH + 36}, 0.4, kInk);
}

} // namespace

// Drawn in layers, each over the one before: grid, cells, camera, overlays, axes, title,
// colour scale.
cv::Mat renderDensityView(const DensityView &view, const RenderOptions &options) {
    const PlotArea area = plotAreaOf(view, options);
    cv::Mat img(area.top + area.height_px + area.bottom, area.left + area.width_px + area.right, CV_8UC3, kPaper);
    const AxisTicks ticks = axisTicksOf(view, area);
    const int maxCount = std::max(1, view.maxCount());
    const double logMax = std::log1p(static_cast<double>(maxCount));

    drawGrid(img, view, area, ticks);
    drawCells(img, view, area, options.density_threshold, logMax);
    drawCamera(img, view, area);
    for (const ViewOverlay &o : options.overlays) drawOverlay(img, area, o);
    drawAxes(img, view, area, ticks);
    drawTitle(img, view, area, options.title);
    drawColourScale(img, area, maxCount, logMax, options.density_threshold);
    return img;
}

void writePngAtomic(const std::string &path, const cv::Mat &image) {
    std::vector<uint8_t> bytes;
    if (image.empty() || !cv::imencode(".png", image, bytes))
        throw std::runtime_error(path + ": cannot encode the picture as PNG");
    // The project's one crash-safe writer: a temporary with a random name, created
    // O_EXCL | O_NOFOLLOW (a planted file or symlink is never written through), renamed.
    writeFileAtomic(path, std::string(bytes.begin(), bytes.end()));
}

} // namespace binocle::method
