// SPDX-License-Identifier: MIT
// Charts: one layout, drawn on two canvases (SVG text and an OpenCV image).
#include "report/chart.hpp"

#include "core/image_io.hpp"
#include "files/atomic_file.hpp"
#include "input/utf8.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace binocle {

namespace {

struct Rgb {
    int r, g, b;
};

// A colour-blind-safe palette (Okabe-Ito).
const Rgb kPalette[] = {{0, 114, 178}, {230, 159, 0}, {0, 158, 115}, {204, 121, 167},
                        {86, 180, 233}, {213, 94, 0},  {240, 228, 66}, {0, 0, 0}};
const Rgb kAxis{40, 40, 40}, kGrid{220, 220, 220}, kBand{235, 245, 235};

Rgb paletteColor(int i) { return kPalette[static_cast<size_t>(i) % (sizeof kPalette / sizeof kPalette[0])]; }

enum class Anchor { Start, Middle, End };

// Drawing primitives both outputs understand.
class Canvas {
public:
    virtual ~Canvas() = default;
    virtual void rect(double x, double y, double w, double h, Rgb fill) = 0;
    virtual void line(double x0, double y0, double x1, double y1, Rgb color, double width, bool dashed = false) = 0;
    virtual void circle(double x, double y, double r, Rgb fill) = 0;
    virtual void text(double x, double y, const std::string &s, double size, Rgb color, Anchor anchor = Anchor::Start,
                      bool vertical = false) = 0;
};


class SvgCanvas : public Canvas {
public:
    SvgCanvas(int w, int h) {
        os_ << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << h << "\" viewBox=\"0 0 " << w
            << " " << h << "\" font-family=\"DejaVu Sans, Arial, sans-serif\">\n";
        rect(0, 0, w, h, {255, 255, 255});
    }
    void rect(double x, double y, double w, double h, Rgb f) override {
        os_ << "<rect x=\"" << x << "\" y=\"" << y << "\" width=\"" << w << "\" height=\"" << h << "\" fill=\"" << color(f)
            << "\"/>\n";
    }
    void line(double x0, double y0, double x1, double y1, Rgb c, double width, bool dashed) override {
        os_ << "<line x1=\"" << x0 << "\" y1=\"" << y0 << "\" x2=\"" << x1 << "\" y2=\"" << y1 << "\" stroke=\"" << color(c)
            << "\" stroke-width=\"" << width << "\"" << (dashed ? " stroke-dasharray=\"6,4\"" : "") << "/>\n";
    }
    void circle(double x, double y, double r, Rgb f) override {
        os_ << "<circle cx=\"" << x << "\" cy=\"" << y << "\" r=\"" << r << "\" fill=\"" << color(f) << "\"/>\n";
    }
    void text(double x, double y, const std::string &s, double size, Rgb c, Anchor a, bool vertical) override {
        const char *anchor = a == Anchor::Start ? "start" : a == Anchor::Middle ? "middle" : "end";
        os_ << "<text x=\"" << x << "\" y=\"" << y << "\" font-size=\"" << size << "\" fill=\"" << color(c)
            << "\" text-anchor=\"" << anchor << "\"";
        if (vertical) os_ << " transform=\"rotate(-90 " << x << " " << y << ")\"";
        os_ << ">" << input::xmlEscape(s) << "</text>\n";
    }
    std::string finish() { return os_.str() + "</svg>\n"; }

private:
    static std::string color(Rgb c) {
        char buf[16];
        std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c.r, c.g, c.b);
        return buf;
    }
    std::ostringstream os_;
};

// Hershey fonts are ASCII only: spell out the Greek letters and symbols we use.
std::string asciiOnly(const std::string &s) {
    static const std::pair<const char *, const char *> kMap[] = {
        {"η", "eta"}, {"ε", "eps"}, {"θ", "theta"}, {"°", " deg"}, {"µ", "u"}, {"≥", ">="}, {"≤", "<="}, {"–", "-"}, {"×", "x"}};
    std::string out = s;
    for (const auto &[from, to] : kMap) {
        for (size_t p = out.find(from); p != std::string::npos; p = out.find(from, p + std::strlen(to)))
            out.replace(p, std::strlen(from), to);
    }
    return out;
}

class MatCanvas : public Canvas {
public:
    MatCanvas(int w, int h) : img_(h, w, CV_8UC3, cv::Scalar(255, 255, 255)) {}
    void rect(double x, double y, double w, double h, Rgb f) override {
        cv::rectangle(img_, cv::Rect(cv::Point(iround(x), iround(y)), cv::Point(iround(x + w), iround(y + h))), bgr(f),
                      cv::FILLED, cv::LINE_AA);
    }
    void line(double x0, double y0, double x1, double y1, Rgb c, double width, bool dashed) override {
        const int t = std::max(1, iround(width));
        if (!dashed) {
            cv::line(img_, {iround(x0), iround(y0)}, {iround(x1), iround(y1)}, bgr(c), t, cv::LINE_AA);
            return;
        }
        const double len = std::hypot(x1 - x0, y1 - y0);
        for (double s = 0; s < len; s += 10) {
            const double e = std::min(len, s + 6);
            cv::line(img_, {iround(x0 + (x1 - x0) * s / len), iround(y0 + (y1 - y0) * s / len)},
                     {iround(x0 + (x1 - x0) * e / len), iround(y0 + (y1 - y0) * e / len)}, bgr(c), t, cv::LINE_AA);
        }
    }
    void circle(double x, double y, double r, Rgb f) override {
        cv::circle(img_, {iround(x), iround(y)}, std::max(1, iround(r)), bgr(f), cv::FILLED, cv::LINE_AA);
    }
    void text(double x, double y, const std::string &s0, double size, Rgb c, Anchor a, bool vertical) override {
        const std::string s = asciiOnly(s0);
        const double scale = size / 30.0;
        int base = 0;
        const cv::Size ts = cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &base);
        const double shift = a == Anchor::Start ? 0 : a == Anchor::Middle ? ts.width / 2.0 : ts.width;
        if (!vertical) {
            cv::putText(img_, s, {iround(x - shift), iround(y)}, cv::FONT_HERSHEY_SIMPLEX, scale, bgr(c), 1, cv::LINE_AA);
            return;
        }
        // Draw horizontally on a strip, rotate it, paste it.
        cv::Mat strip(ts.height + base + 4, ts.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
        cv::putText(strip, s, {2, ts.height + 1}, cv::FONT_HERSHEY_SIMPLEX, scale, bgr(c), 1, cv::LINE_AA);
        cv::Mat rotated;
        cv::rotate(strip, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
        const int x0 = iround(x - rotated.cols + base), y0 = iround(y - rotated.rows + shift);
        cv::Rect dst(x0, y0, rotated.cols, rotated.rows);
        dst &= cv::Rect(0, 0, img_.cols, img_.rows);
        if (dst.area() > 0) rotated(cv::Rect(dst.x - x0, dst.y - y0, dst.width, dst.height)).copyTo(img_(dst));
    }
    const cv::Mat &image() const { return img_; }

private:
    static int iround(double v) { return static_cast<int>(std::lround(v)); }
    static cv::Scalar bgr(Rgb c) { return cv::Scalar(c.b, c.g, c.r); }
    cv::Mat img_;
};

std::string fmt(double v) {
    char buf[32];
    if (std::fabs(v) >= 100 || v == std::floor(v)) std::snprintf(buf, sizeof buf, "%.0f", v);
    else std::snprintf(buf, sizeof buf, "%.2g", v);
    return buf;
}

// A "nice" tick step for a span.
double niceStep(double span, int wanted) {
    const double raw = span / std::max(1, wanted);
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
        if (raw <= m * mag) return m * mag;
    return 10 * mag;
}

struct Plot {
    double left, top, right, bottom; // plot area in pixels
};

void axesY(Canvas &c, const Plot &p, double ymin, double ymax, const std::string &label, int width) {
    const double step = niceStep(ymax - ymin, 5);
    for (double v = std::ceil(ymin / step) * step; v <= ymax + 1e-9; v += step) {
        const double y = p.bottom - (v - ymin) / (ymax - ymin) * (p.bottom - p.top);
        c.line(p.left, y, p.right, y, kGrid, 1);
        c.text(p.left - 8, y + 5, fmt(v), 14, kAxis, Anchor::End);
    }
    c.line(p.left, p.top, p.left, p.bottom, kAxis, 1.5);
    c.line(p.left, p.bottom, p.right, p.bottom, kAxis, 1.5);
    c.text(22, (p.top + p.bottom) / 2, label, 15, kAxis, Anchor::Middle, true);
    (void)width;
}

void legend(Canvas &c, const std::vector<std::string> &series, double x, double y) {
    for (size_t i = 0; i < series.size(); ++i) {
        c.rect(x, y + 22.0 * i - 11, 14, 14, paletteColor(static_cast<int>(i)));
        c.text(x + 20, y + 22.0 * i + 1, series[i], 14, kAxis);
    }
}

void draw(Canvas &c, const BarChart &ch, int w, int h) {
    const double legendWidth = ch.series.empty() ? 0 : 150;
    const Plot p{70, 50, w - 20 - legendWidth, h - 70.0};
    c.text(w / 2.0, 30, ch.title, 18, kAxis, Anchor::Middle);
    const double ymin = ch.y_min, ymax = ch.y_max > ch.y_min ? ch.y_max : ch.y_min + 1;
    axesY(c, p, ymin, ymax, ch.y_label, w);
    auto yOf = [&](double v) { return p.bottom - (std::clamp(v, ymin, ymax) - ymin) / (ymax - ymin) * (p.bottom - p.top); };
    for (double r : ch.reference_lines) c.line(p.left, yOf(r), p.right, yOf(r), {150, 150, 150}, 1.2, true);
    const size_t ng = std::max<size_t>(1, ch.groups.size()), ns = std::max<size_t>(1, ch.series.size());
    const double gw = (p.right - p.left) / ng, bw = gw * 0.8 / ns;
    for (size_t g = 0; g < ch.groups.size(); ++g) {
        const double gx = p.left + g * gw + gw * 0.1;
        for (size_t s = 0; s < ch.groups[g].values.size() && s < ns; ++s) {
            const double v = ch.groups[g].values[s];
            const double x = gx + s * bw;
            if (!std::isfinite(v)) {
                c.text(x + bw / 2, p.bottom - 6, "n/a", 11, {150, 150, 150}, Anchor::Middle);
                continue;
            }
            const double y = yOf(v);
            c.rect(x + 1, y, bw - 2, p.bottom - y, paletteColor(static_cast<int>(s)));
            const auto &grp = ch.groups[g];
            const double lo = s < grp.low.size() ? grp.low[s] : NAN, hi = s < grp.high.size() ? grp.high[s] : NAN;
            double labelY = y;
            if (std::isfinite(lo) && std::isfinite(hi)) { // whisker with caps
                const double cx = x + bw / 2, cap = std::min(6.0, bw / 4);
                c.line(cx, yOf(lo), cx, yOf(hi), kAxis, 1.3);
                c.line(cx - cap, yOf(lo), cx + cap, yOf(lo), kAxis, 1.3);
                c.line(cx - cap, yOf(hi), cx + cap, yOf(hi), kAxis, 1.3);
                labelY = std::min(y, yOf(hi));
            }
            if (s < grp.reference.size() && std::isfinite(grp.reference[s])) {
                const double rx = x + bw / 2, ry = yOf(grp.reference[s]);
                c.line(rx - 6, ry, rx, ry - 6, kAxis, 2);
                c.line(rx, ry - 6, rx + 6, ry, kAxis, 2);
                c.line(rx + 6, ry, rx, ry + 6, kAxis, 2);
                c.line(rx, ry + 6, rx - 6, ry, kAxis, 2);
                labelY = std::min(labelY, ry - 6);
            }
            c.text(x + bw / 2, labelY - 4, fmt(v), 11, kAxis, Anchor::Middle);
        }
        c.text(p.left + g * gw + gw / 2, p.bottom + 22, ch.groups[g].label, 14, kAxis, Anchor::Middle);
    }
    legend(c, ch.series, p.right + 20, p.top + 10);
    const bool anyReference = std::any_of(ch.groups.begin(), ch.groups.end(), [](const BarGroup &g) {
        return std::any_of(g.reference.begin(), g.reference.end(), [](double v) { return std::isfinite(v); });
    });
    if (anyReference) {
        const double lx = p.right + 27, ly = p.top + 10 + 22.0 * ch.series.size();
        c.line(lx - 6, ly - 4, lx, ly - 10, kAxis, 2);
        c.line(lx, ly - 10, lx + 6, ly - 4, kAxis, 2);
        c.line(lx + 6, ly - 4, lx, ly + 2, kAxis, 2);
        c.line(lx, ly + 2, lx - 6, ly - 4, kAxis, 2);
        c.text(p.right + 40, ly + 1, ch.reference_label.empty() ? "reference" : ch.reference_label, 14, kAxis);
    }
}

void draw(Canvas &c, const ScatterChart &ch, int w, int h) {
    double xmin = ch.x_min, xmax = ch.x_max, ymin = ch.y_min, ymax = ch.y_max;
    if (xmax <= xmin) {
        xmin = 0;
        xmax = 1;
        for (const auto &pt : ch.points)
            if (std::isfinite(pt.x)) xmax = std::max(xmax, pt.x * 1.1);
    }
    if (ymax <= ymin) {
        ymin = 0;
        ymax = 100;
    }
    const double legendWidth = ch.series.size() > 1 ? 150 : 0;
    const Plot p{70, 50, w - 20 - legendWidth, h - 70.0};
    c.text(w / 2.0, 30, ch.title, 18, kAxis, Anchor::Middle);
    auto xOf = [&](double v) { return p.left + (std::clamp(v, xmin, xmax) - xmin) / (xmax - xmin) * (p.right - p.left); };
    auto yOf = [&](double v) { return p.bottom - (std::clamp(v, ymin, ymax) - ymin) / (ymax - ymin) * (p.bottom - p.top); };
    if (ch.band_max > ch.band_min) c.rect(xOf(ch.band_min), p.top, xOf(ch.band_max) - xOf(ch.band_min), p.bottom - p.top, kBand);
    axesY(c, p, ymin, ymax, ch.y_label, w);
    const double step = niceStep(xmax - xmin, 8);
    for (double v = std::ceil(xmin / step) * step; v <= xmax + 1e-9; v += step) {
        c.line(xOf(v), p.bottom, xOf(v), p.bottom + 5, kAxis, 1);
        c.text(xOf(v), p.bottom + 20, fmt(v), 14, kAxis, Anchor::Middle);
    }
    c.text((p.left + p.right) / 2, h - 18.0, ch.x_label, 15, kAxis, Anchor::Middle);
    for (const auto &pt : ch.points) {
        if (!std::isfinite(pt.x) || !std::isfinite(pt.y)) continue;
        if (std::isfinite(pt.y_low) && std::isfinite(pt.y_high)) {
            c.line(xOf(pt.x), yOf(pt.y_low), xOf(pt.x), yOf(pt.y_high), paletteColor(pt.series), 1.3);
            c.line(xOf(pt.x) - 4, yOf(pt.y_low), xOf(pt.x) + 4, yOf(pt.y_low), paletteColor(pt.series), 1.3);
            c.line(xOf(pt.x) - 4, yOf(pt.y_high), xOf(pt.x) + 4, yOf(pt.y_high), paletteColor(pt.series), 1.3);
        }
        c.circle(xOf(pt.x), yOf(pt.y), 5, paletteColor(pt.series));
        if (!pt.label.empty()) c.text(xOf(pt.x) + 7, yOf(pt.y) - 6, pt.label, 11, kAxis);
    }
    if (ch.series.size() > 1) legend(c, ch.series, p.right + 20, p.top + 10);
}

// Either kind of chart, drawn on either canvas.
template <class Chart> std::string svgOf(const Chart &chart, int width, int height) {
    SvgCanvas c(width, height);
    draw(c, chart, width, height);
    return c.finish();
}

template <class Chart> cv::Mat imageOf(const Chart &chart, int width, int height) {
    MatCanvas c(width, height);
    draw(c, chart, width, height);
    return c.image();
}

// STEM.png and STEM.svg, each at its kind's default size.
template <class Chart> void writeBoth(const std::string &stem, const Chart &chart) {
    writeImage(stem + ".png", toImage(chart));
    writeFileAtomic(stem + ".svg", toSvg(chart));
}

} // namespace

std::string toSvg(const BarChart &chart, int width, int height) { return svgOf(chart, width, height); }
cv::Mat toImage(const BarChart &chart, int width, int height) { return imageOf(chart, width, height); }
std::string toSvg(const ScatterChart &chart, int width, int height) { return svgOf(chart, width, height); }
cv::Mat toImage(const ScatterChart &chart, int width, int height) { return imageOf(chart, width, height); }
void writeChart(const std::string &stem, const BarChart &chart) { writeBoth(stem, chart); }
void writeChart(const std::string &stem, const ScatterChart &chart) { writeBoth(stem, chart); }

} // namespace binocle
