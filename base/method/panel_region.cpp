// SPDX-License-Identifier: MIT
// The panel's region in the front view of its range band (panel_region.hpp).
#include "method/panel_region.hpp"

#include "method/density_grid.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace binocle::method {

namespace {
std::string mm(double v) {
    std::ostringstream s;
    s.precision(0);
    s << std::fixed << v << " mm";
    return s.str();
}

// Dense cells, without the specks smaller than min_cells.
cv::Mat denseCells(const cv::Mat &counts, int threshold, int min_cells) {
    cv::Mat dense, labels, stats, centroids;
    cv::compare(counts, threshold, dense, cv::CMP_GE);
    const int n = cv::connectedComponentsWithStats(dense, labels, stats, centroids, 8, CV_32S);
    for (int l = 1; l < n; ++l)
        if (stats.at<int>(l, cv::CC_STAT_AREA) < min_cells) dense.setTo(0, labels == l);
    return dense;
}

// Median of a list of cell indices, rounded outwards (up for an upper edge).
int medianCell(std::vector<float> v, bool upper) {
    const double m = median(std::move(v));
    return static_cast<int>(upper ? std::ceil(m) : std::floor(m));
}

// The panel's lateral edges are where most of its rows end, and its top where most of
// its columns end: a smear or a strip of clutter confined to a few rows (a matcher's
// fill into the sky beside the top cubes, ground points lifted into the band along the
// bottom) or a few columns is cut off where it leaves the panel's outline. Rows and
// columns with fewer than min_cells cells of the region do not vote.
void trimToMajority(cv::Mat &region, int min_cells) {
    std::vector<float> lefts, rights, tops;
    for (int r = 0; r < region.rows; ++r) {
        const uint8_t *row = region.ptr<uint8_t>(r);
        int first = -1, last = -1, n = 0;
        for (int c = 0; c < region.cols; ++c)
            if (row[c]) {
                if (first < 0) first = c;
                last = c;
                ++n;
            }
        if (n < min_cells) continue;
        lefts.push_back(static_cast<float>(first));
        rights.push_back(static_cast<float>(last));
    }
    for (int c = 0; c < region.cols; ++c) {
        int top = -1, n = 0;
        for (int r = 0; r < region.rows; ++r)
            if (region.at<uint8_t>(r, c)) {
                top = r;
                ++n;
            }
        if (n >= min_cells) tops.push_back(static_cast<float>(top));
    }
    if (lefts.empty() || tops.empty()) return;
    const int left = medianCell(lefts, false), right = medianCell(rights, true), top = medianCell(tops, true);
    for (int r = 0; r < region.rows; ++r)
        for (int c = 0; c < region.cols; ++c)
            if (c < left || c > right || r > top) region.at<uint8_t>(r, c) = 0;
}
} // namespace

PanelRegion selectPanelRegion(const std::vector<float> &x, const std::vector<float> &z, const PanelRegionOptions &o) {
    PanelRegion out;
    out.members.assign(x.size(), 0);
    if (x.empty() || x.size() != z.size()) {
        out.reason = "no points in the range band";
        return out;
    }
    const double cell = o.cell_mm;
    const auto [xmin, xmax] = std::minmax_element(x.begin(), x.end());
    const auto [zmin, zmax] = std::minmax_element(z.begin(), z.end());
    const double u0 = (std::floor(*xmin / cell) - 1) * cell, v0 = (std::floor(*zmin / cell) - 1) * cell;
    const int cols = static_cast<int>(std::floor((*xmax - u0) / cell)) + 2;
    const int rows = static_cast<int>(std::floor((*zmax - v0) / cell)) + 2;
    cv::Mat counts = cv::Mat::zeros(rows, cols, CV_32S);
    std::vector<cv::Point> cellOf(x.size());
    for (size_t i = 0; i < x.size(); ++i) {
        cellOf[i] = {static_cast<int>(std::floor((x[i] - u0) / cell)), static_cast<int>(std::floor((z[i] - v0) / cell))};
        ++counts.at<int32_t>(cellOf[i]);
    }
    // The columns at the stated position, and the panel's typical cell there.
    const int seedLo = std::clamp(static_cast<int>(std::floor((o.seed_x_mm - o.seed_half_width_mm - u0) / cell)), 0, cols);
    const int seedHi = std::clamp(static_cast<int>(std::ceil((o.seed_x_mm + o.seed_half_width_mm - u0) / cell)), 0, cols);
    std::vector<float> seedCounts;
    for (int r = 0; r < rows; ++r)
        for (int c = seedLo; c < seedHi; ++c)
            if (counts.at<int32_t>(r, c) >= o.density_threshold) seedCounts.push_back(static_cast<float>(counts.at<int32_t>(r, c)));
    if (seedCounts.empty()) {
        out.reason = "no occupied front-view cell within " + mm(o.seed_half_width_mm) + " of the stated lateral position " +
                     mm(o.seed_x_mm);
        return out;
    }
    out.reference_count = percentile(seedCounts, 75);
    out.threshold = std::max(o.density_threshold, static_cast<int>(std::ceil(o.relative_density * out.reference_count)));

    // Dense cells; gaps up to bridge_mm closed; the region that holds most of the dense
    // cells at the stated position is the panel.
    const cv::Mat dense = denseCells(counts, out.threshold, o.min_cells);
    const int reach = std::max(0, static_cast<int>(std::ceil(o.bridge_mm / cell / 2)));
    cv::Mat joined;
    cv::dilate(dense, joined, cv::getStructuringElement(cv::MORPH_RECT, {2 * reach + 1, 2 * reach + 1}));
    cv::Mat labels;
    const int n = cv::connectedComponents(joined, labels, 8, CV_32S);
    std::vector<int64_t> atSeed(static_cast<size_t>(n), 0);
    for (int r = 0; r < rows; ++r)
        for (int c = seedLo; c < seedHi; ++c)
            if (dense.at<uint8_t>(r, c)) atSeed[static_cast<size_t>(labels.at<int32_t>(r, c))] += counts.at<int32_t>(r, c);
    cv::Mat region = cv::Mat::zeros(rows, cols, CV_8U);
    for (int l = 1; l < n; ++l)
        if (atSeed[static_cast<size_t>(l)] > 0) region.setTo(255, dense & (labels == l));
    if (cv::countNonZero(region) == 0) {
        out.reason = "no region of cells with " + std::to_string(out.threshold) + " or more points within " +
                     mm(o.seed_half_width_mm) + " of the stated lateral position " + mm(o.seed_x_mm);
        return out;
    }
    trimToMajority(region, o.min_cells);
    // Its points: in its cells or next to them (edges under the threshold belong to it).
    cv::Mat near;
    cv::dilate(region, near, cv::Mat::ones(3, 3, CV_8U));
    for (size_t i = 0; i < x.size(); ++i) {
        if (!near.at<uint8_t>(cellOf[i])) continue;
        out.members[i] = 1;
        ++out.member_count;
    }
    out.found = true;
    return out;
}

} // namespace binocle::method
