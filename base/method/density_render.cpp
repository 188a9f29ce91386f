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

} // namespace

cv::Mat renderDensityView(const DensityView &view, const RenderOptions &options) {
    const int cols = std::max(1, view.cols()), rows = std::max(1, view.rows());
    int s = std::max(1, static_cast<int>(std::lround(static_cast<double>(options.target_size_px) / std::max(cols, rows))));
    while (s > 1 && std::max(cols, rows) * s > 1600) --s;
    const int W = cols * s, H = rows * s;
    const int left = 78, right = 130, top = 56, bottom = 62;
    cv::Mat img(top + H + bottom, left + W + right, CV_8UC3, kPaper);
    const double mmPerPx = view.cell_mm / s;
    auto px = [&](double u_mm) { return left + static_cast<int>(std::lround((u_mm - view.u.min_mm) / mmPerPx)); };
    auto py = [&](double v_mm) { return top + H - static_cast<int>(std::lround((v_mm - view.v.min_mm) / mmPerPx)); };

    // Grid lines at the ticks, under the cells.
    const double uStep = tickStep(mmPerPx, 60), vStep = tickStep(mmPerPx, 45);
    const double u0 = std::ceil(view.u.min_mm / uStep) * uStep, v0 = std::ceil(view.v.min_mm / vStep) * vStep;
    for (double u = u0; u <= view.u.max_mm + 1e-6; u += uStep) cv::line(img, {px(u), top}, {px(u), top + H}, kGrid, 1);
    for (double v = v0; v <= view.v.max_mm + 1e-6; v += vStep) cv::line(img, {left, py(v)}, {left + W, py(v)}, kGrid, 1);

    // Cells: log scale so that sparse outliers and a dense panel are both visible.
    const int maxCount = std::max(1, view.maxCount());
    const double logMax = std::log1p(static_cast<double>(maxCount));
    for (int r = 0; r < view.rows(); ++r)
        for (int c = 0; c < view.cols(); ++c) {
            const int n = view.count(r, c);
            if (n <= 0) continue;
            cv::Vec3b color = viridis(std::log1p(static_cast<double>(n)) / logMax);
            if (n < options.density_threshold) color = pale(color);
            const cv::Rect cell(left + c * s, top + H - (r + 1) * s, s, s);
            img(cell).setTo(cv::Scalar(color[0], color[1], color[2]));
        }

    // The camera (the ground frame's origin) in the top view.
    if (view.view == View::Top && view.u.contains(0) && view.v.min_mm <= 0) {
        const cv::Point c(px(0), std::min(py(0), top + H));
        std::vector<cv::Point> tri{{c.x, c.y - 12}, {c.x - 8, c.y}, {c.x + 8, c.y}};
        cv::fillConvexPoly(img, tri, cv::Scalar(60, 60, 230), cv::LINE_AA);
        text(img, "camera", {c.x + 10, c.y - 4}, 0.4, cv::Scalar(60, 60, 230));
    }

    for (const ViewOverlay &o : options.overlays) {
        const cv::Point a(px(o.u.min_mm), py(o.v.max_mm)), b(px(o.u.max_mm), py(o.v.min_mm));
        if (!o.cells.empty() && o.cell_mm > 0) {
            // The outline of the cells the reading took, over the counts it read them from.
            cv::Mat mask = cv::Mat::zeros(img.size(), CV_8U);
            for (const auto &c : o.cells)
                cv::rectangle(mask, cv::Point(px(c[0]), py(c[1] + o.cell_mm)), cv::Point(px(c[0] + o.cell_mm) - 1, py(c[1]) - 1),
                              255, cv::FILLED);
            mask(cv::Rect(0, 0, img.cols, top)).setTo(0);
            std::vector<std::vector<cv::Point>> contours;
            cv::findContours(mask, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
            cv::drawContours(img, contours, -1, o.color, 1, cv::LINE_8);
            cv::rectangle(img, a, b, o.color, 1, cv::LINE_AA);
        } else {
            cv::rectangle(img, a, b, o.color, 2, cv::LINE_AA);
        }
        if (!o.label.empty()) {
            const cv::Point at(std::clamp(a.x, left, left + W - 10), std::max(a.y - 5, top + 12));
            text(img, o.label, at, 0.42, o.color, 1);
        }
    }

    // Frame, ticks and labels.
    cv::rectangle(img, {left, top}, {left + W, top + H}, kInk, 1);
    for (double u = u0; u <= view.u.max_mm + 1e-6; u += uStep) {
        const int x = px(u);
        cv::line(img, {x, top + H}, {x, top + H + 5}, kInk, 1);
        const std::string t = metres(u);
        text(img, t, {x - textSize(t, 0.42).width / 2, top + H + 20}, 0.42, kInk);
    }
    for (double v = v0; v <= view.v.max_mm + 1e-6; v += vStep) {
        const int y = py(v);
        cv::line(img, {left - 5, y}, {left, y}, kInk, 1);
        const std::string t = metres(v);
        const cv::Size sz = textSize(t, 0.42);
        text(img, t, {left - 9 - sz.width, y + sz.height / 2}, 0.42, kInk);
    }
    const std::string ut = axisTitle(view.view, true);
    text(img, ut, {left + W / 2 - textSize(ut, 0.5).width / 2, top + H + 48}, 0.5, kInk);
    verticalText(img, axisTitle(view.view, false), {18, top + H / 2}, 0.5);

    std::string title = options.title;
    if (title.empty()) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "%s - %lld points, cell %g mm", viewTitle(view.view).c_str(),
                      static_cast<long long>(view.total()), view.cell_mm);
        title = buf;
    }
    double titleScale = 0.6; // smaller for a narrow view, so that the title stays whole
    while (titleScale > 0.35 && left + textSize(title, titleScale).width > img.cols - 8) titleScale -= 0.05;
    text(img, title, {std::max(8, std::min(left, img.cols - 8 - textSize(title, titleScale).width)), 34}, titleScale, kInk, 1);

    // Colour scale: log(1 + count) from 1 to the largest count, with the threshold.
    const int barX = left + W + 28, barW = 16, barH = std::min(H, 320), barY = top;
    for (int y = 0; y < barH; ++y) {
        const double t = 1.0 - static_cast<double>(y) / std::max(1, barH - 1);
        const double n = std::expm1(t * logMax);
        cv::Vec3b color = viridis(t);
        if (n < options.density_threshold) color = pale(color);
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
    if (options.density_threshold > 1 && options.density_threshold < maxCount)
        barMark(options.density_threshold, "thr " + std::to_string(options.density_threshold));
    text(img, "points", {barX - 6, barY + barH + 20}, 0.4, kInk);
    text(img, "per cell", {barX - 6, barY + barH + 36}, 0.4, kInk);
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
