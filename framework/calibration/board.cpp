// SPDX-License-Identifier: MIT
// The calibration chessboard: parse, find with sub-pixel corners, measure.
#include "calibration/board.hpp"

#include "core/error.hpp"
#include "input/integer_range.hpp"

#include <binocle/text.hpp>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace binocle {

std::vector<cv::Point3f> BoardSpec::objectPoints() const {
    std::vector<cv::Point3f> points;
    points.reserve(static_cast<size_t>(cols * rows));
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
            points.emplace_back(static_cast<float>(c * square_mm), static_cast<float>(r * square_mm), 0.0f);
    return points;
}

BoardSpec BoardSpec::parse(const std::string &board, double square_mm) {
    // COLSxROWS, each count read by the one number reader: "09x6" is refused like any
    // number with a leading zero, not read as 9.
    const auto x = board.find_first_of("xX");
    const std::string shown = sdk::printable(board);
    if (x == std::string::npos)
        throw Error("--board '" + shown + "': expected COLSxROWS, the inner corners per row and per column, e.g. 9x6");
    BoardSpec b;
    const std::pair<std::string, int *> parts[] = {{board.substr(0, x), &b.cols}, {board.substr(x + 1), &b.rows}};
    for (const auto &[text, count] : parts) {
        int64_t v = 0;
        std::string why;
        if (!input::parseInteger(text, v, &why, 0, 999))
            throw Error("--board '" + shown + "': '" + sdk::printable(text) + "' is not valid: " + why +
                        " (COLSxROWS, the inner corners per row and per column, e.g. 9x6)");
        *count = static_cast<int>(v);
    }
    if (b.cols < 2 || b.rows < 2)
        throw Error("--board '" + shown + "': a chessboard needs at least 2x2 inner corners");
    if (b.cols == b.rows)
        throw Error("--board '" + shown +
                    "': a square pattern has no distinct orientation; use a board with different counts (e.g. 9x6)");
    if (!(square_mm > 0) || !std::isfinite(square_mm)) {
        std::ostringstream shown; // as written ("-5"), not std::to_string's "-5.000000"
        shown << square_mm;
        throw Error("--square-mm " + shown.str() + ": expected the side of one square in mm, > 0");
    }
    b.square_mm = square_mm;
    return b;
}

namespace {

double outlineAreaPercent(const std::vector<cv::Point2f> &corners, const BoardSpec &b, cv::Size image) {
    // The four outer corners, in order around the board.
    const std::vector<cv::Point2f> quad = {corners[0], corners[static_cast<size_t>(b.cols - 1)],
                                           corners[static_cast<size_t>(b.cols * b.rows - 1)],
                                           corners[static_cast<size_t>((b.rows - 1) * b.cols)]};
    return 100.0 * std::abs(cv::contourArea(quad)) / (static_cast<double>(image.width) * image.height);
}

double smallestSpacingPx(const std::vector<cv::Point2f> &corners, const BoardSpec &b) {
    double best = 1e9;
    for (int r = 0; r < b.rows; ++r)
        for (int c = 0; c < b.cols; ++c) {
            const cv::Point2f p = corners[static_cast<size_t>(r * b.cols + c)];
            if (c + 1 < b.cols) best = std::min(best, cv::norm(corners[static_cast<size_t>(r * b.cols + c + 1)] - p));
            if (r + 1 < b.rows) best = std::min(best, cv::norm(corners[static_cast<size_t>((r + 1) * b.cols + c)] - p));
        }
    return best;
}

double bilinear(const cv::Mat &grey, cv::Point2f p) {
    const int x = static_cast<int>(std::floor(p.x)), y = static_cast<int>(std::floor(p.y));
    if (x < 0 || y < 0 || x + 1 >= grey.cols || y + 1 >= grey.rows) return -1;
    const double fx = p.x - x, fy = p.y - y;
    const uint8_t *r0 = grey.ptr<uint8_t>(y), *r1 = grey.ptr<uint8_t>(y + 1);
    return (1 - fy) * ((1 - fx) * r0[x] + fx * r0[x + 1]) + fy * ((1 - fx) * r1[x] + fx * r1[x + 1]);
}

// Width of the 10 %-90 % rise across the edge between two squares, measured through the
// midpoint of two neighbouring corners, perpendicular to the line joining them; < 0
// when the profile is unusable (image border, no contrast).
double riseWidthPx(const cv::Mat &grey, cv::Point2f a, cv::Point2f b) {
    const cv::Point2f d = b - a;
    const double length = std::hypot(d.x, d.y);
    if (length < 4) return -1;
    const cv::Point2f n(static_cast<float>(-d.y / length), static_cast<float>(d.x / length)), m = (a + b) * 0.5f;
    const double half = 0.4 * length, step = 0.1;
    std::vector<double> profile;
    for (double t = -half; t <= half; t += step) {
        const double g = bilinear(grey, m + n * static_cast<float>(t));
        if (g < 0) return -1;
        profile.push_back(g);
    }
    const size_t tail = std::max<size_t>(profile.size() / 5, 1);
    double lo = 0, hi = 0;
    for (size_t i = 0; i < tail; ++i) {
        lo += profile[i];
        hi += profile[profile.size() - 1 - i];
    }
    lo /= static_cast<double>(tail);
    hi /= static_cast<double>(tail);
    if (std::abs(hi - lo) < 20) return -1;
    // Rising from lo to hi: the last sample below 10 % and the first above 90 % of the step.
    const double sign = hi > lo ? 1 : -1, l10 = lo + 0.1 * (hi - lo), l90 = lo + 0.9 * (hi - lo);
    size_t i10 = 0, i90 = profile.size() - 1;
    for (size_t i = 0; i < profile.size(); ++i)
        if (sign * (profile[i] - l10) < 0) i10 = i;
    for (size_t i = profile.size(); i-- > 0;)
        if (sign * (profile[i] - l90) > 0) i90 = i;
    return i90 > i10 ? static_cast<double>(i90 - i10) * step : step;
}

// Median rise width over every edge between neighbouring inner corners.
double edgeWidthPx(const cv::Mat &grey, const std::vector<cv::Point2f> &corners, const BoardSpec &b) {
    std::vector<double> widths;
    for (int r = 0; r < b.rows; ++r)
        for (int c = 0; c < b.cols; ++c) {
            const size_t i = static_cast<size_t>(r * b.cols + c);
            if (c + 1 < b.cols) widths.push_back(riseWidthPx(grey, corners[i], corners[i + 1]));
            if (r + 1 < b.rows) widths.push_back(riseWidthPx(grey, corners[i], corners[i + static_cast<size_t>(b.cols)]));
        }
    widths.erase(std::remove_if(widths.begin(), widths.end(), [](double w) { return w < 0; }), widths.end());
    if (widths.size() < 4) return -1;
    std::nth_element(widths.begin(), widths.begin() + static_cast<long>(widths.size() / 2), widths.end());
    return widths[widths.size() / 2];
}

} // namespace

BoardView findBoard(const cv::Mat &image, const BoardSpec &board, bool fast) {
    BoardView v;
    if (image.empty()) return v;
    cv::Mat grey;
    if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    else if (image.channels() == 4) cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
    else grey = image;
    if (grey.depth() != CV_8U) grey.convertTo(grey, CV_8U);

    int flags = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE;
    if (fast) flags |= cv::CALIB_CB_FAST_CHECK;
    if (cv::findChessboardCorners(grey, board.patternSize(), v.corners, flags)) {
        // The refinement window must stay inside one square, or it sees the next corner.
        const int half = std::clamp(static_cast<int>(smallestSpacingPx(v.corners, board) / 2.0) - 1, 2, 11);
        cv::cornerSubPix(grey, v.corners, cv::Size(half, half), cv::Size(-1, -1),
                         cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 0.001));
        v.found = true;
        v.detector = "classic";
    } else if (!fast) {
        v.corners.clear();
        if (cv::findChessboardCornersSB(grey, board.patternSize(), v.corners,
                                        cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY)) {
            v.found = true;
            v.detector = "sb";
        }
    }
    if (!v.found) {
        v.corners.clear();
        return v;
    }
    v.area_percent = outlineAreaPercent(v.corners, board, grey.size());
    v.edge_width_px = edgeWidthPx(grey, v.corners, board);
    return v;
}

double meanCornerShiftPx(const std::vector<cv::Point2f> &a, const std::vector<cv::Point2f> &b) {
    if (a.empty() || a.size() != b.size()) return 1e9;
    double sum = 0;
    for (size_t i = 0; i < a.size(); ++i) sum += cv::norm(a[i] - b[i]);
    return sum / static_cast<double>(a.size());
}

double maxCornerShiftPx(const std::vector<cv::Point2f> &a, const std::vector<cv::Point2f> &b) {
    if (a.empty() || a.size() != b.size()) return 1e9;
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, static_cast<double>(cv::norm(a[i] - b[i])));
    return worst;
}

} // namespace binocle
