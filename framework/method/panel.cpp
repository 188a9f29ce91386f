// SPDX-License-Identifier: MIT
// X', Y', Z' of the E1 test panel, read from the density grids (README.md: the method).
#include "method/panel.hpp"

#include "method/ground_plane.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace binocle::method {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string mm(double v) {
    std::ostringstream s;
    s.precision(0);
    s << std::fixed << v << " mm";
    return s.str();
}

// The centre of the densest band [c - margin, c + margin] of range values within `search`
// (cell-sized steps), and how many values it holds.
std::pair<double, int64_t> densestBand(std::vector<float> ys, Extent search, double margin, double step) {
    std::sort(ys.begin(), ys.end());
    double best = kNaN;
    int64_t bestCount = 0;
    for (double c = search.min_mm + step / 2; c < search.max_mm; c += step) {
        const auto lo = std::lower_bound(ys.begin(), ys.end(), static_cast<float>(c - margin));
        const auto hi = std::upper_bound(ys.begin(), ys.end(), static_cast<float>(c + margin));
        const int64_t n = hi - lo;
        if (n > bestCount) {
            bestCount = n;
            best = c;
        }
    }
    return {best, bestCount};
}
} // namespace

PanelReading::PanelReading()
    : width_mm(kNaN), range_mm(kNaN), height_mm(kNaN), x_min_mm(kNaN), x_max_mm(kNaN), z_bottom_mm(kNaN),
      z_top_mm(kNaN), ground_z_mm(kNaN) {}

PanelReading readPanel(const CloudView &cloud, const PanelReadingOptions &o) {
    const GridSpec &g = o.grid;
    g.validate();
    if (!(o.range_margin_mm > 0)) throw std::invalid_argument("range margin " + mm(o.range_margin_mm) + ": expected > 0");
    if (!(o.range_search_percent >= 0))
        throw std::invalid_argument("range search " + std::to_string(o.range_search_percent) + " %: expected >= 0");
    const Extent lateral = o.lateral.valid() ? o.lateral : g.x;
    Extent search = g.y;
    if (o.expected_range_mm > 0) {
        const double s = o.expected_range_mm * o.range_search_percent / 100.0;
        search = {std::max(g.y.min_mm, o.expected_range_mm - s), std::min(g.y.max_mm, o.expected_range_mm + s)};
        if (!search.valid()) search = {o.expected_range_mm - 1, o.expected_range_mm + 1}; // outside the grid
    }
    auto inWindow = [&](size_t i) {
        return cloud.finite(i) && lateral.contains(cloud.x(i)) && g.x.contains(cloud.x(i)) &&
               g.y.contains(cloud.y(i)) && g.z.contains(cloud.z(i));
    };

    PanelReading r;
    // 1. The range band: the densest band of points above the ground near the expected range.
    std::vector<float> ys;
    for (size_t i = 0; i < cloud.count; ++i)
        if (inWindow(i) && cloud.z(i) >= g.ground_band_mm && cloud.y(i) >= search.min_mm - o.range_margin_mm &&
            cloud.y(i) < search.max_mm + o.range_margin_mm)
            ys.push_back(cloud.y(i));
    const auto [centre, inBand] = densestBand(ys, search, o.range_margin_mm, g.cell_mm);
    if (inBand < o.min_points) {
        r.reason = "no panel: " + std::to_string(inBand) + " points above the ground in the densest range band of " +
                   mm(2 * o.range_margin_mm) + " between " + mm(search.min_mm) + " and " + mm(search.max_mm) +
                   " (at least " + std::to_string(o.min_points) + " expected)";
        return r;
    }
    // Centred again on the median range of what it holds, so that the band is symmetric
    // about the panel's face.
    std::vector<float> inside;
    for (float y : ys)
        if (y >= centre - o.range_margin_mm && y <= centre + o.range_margin_mm) inside.push_back(y);
    const double centred = median(inside);
    r.band = {centred - o.range_margin_mm, centred + o.range_margin_mm};

    // 2. The panel's points in that band, above the ground, and its front view (X, Z).
    std::vector<float> px, py, pz;
    for (size_t i = 0; i < cloud.count; ++i) {
        if (!inWindow(i) || !r.band.contains(cloud.y(i)) || cloud.z(i) < g.ground_band_mm) continue;
        px.push_back(cloud.x(i));
        py.push_back(cloud.y(i));
        pz.push_back(cloud.z(i));
    }
    const PlanarExtent front = planarExtent(px, pz, g.cell_mm, g.density_threshold, g.min_object_cells);
    if (!front.found || front.member_count < o.min_points) {
        r.reason = "no panel: " + std::to_string(front.member_count) + " points in occupied front-view cells (" +
                   std::to_string(g.density_threshold) + " or more points per " + mm(g.cell_mm) +
                   " cell) in the range band " + mm(r.band.min_mm) + " .. " + mm(r.band.max_mm) + " (at least " +
                   std::to_string(o.min_points) + " expected)";
        return r;
    }
    std::vector<float> panelY;
    panelY.reserve(static_cast<size_t>(front.member_count));
    for (size_t i = 0; i < py.size(); ++i)
        if (front.members[i]) panelY.push_back(py[i]);
    r.points = front.member_count;

    // 3. X' from the front view's lateral edges, Y' the median range of the panel's points.
    r.x_min_mm = front.u.min_mm;
    r.x_max_mm = front.u.max_mm;
    r.width_mm = r.x_max_mm - r.x_min_mm;
    r.range_mm = median(panelY);

    // 4. Z': from the upper edge down to the ground the panel stands on, read where the
    // panel stands on the ground plane fitted to the whole cloud (so that the panel's
    // own lowest points do not count as ground), or to its lower edge when it floats.
    r.z_top_mm = front.v.max_mm;
    const GroundPlane ground = fitGroundPlane(cloud, GroundPlaneOptions{});
    r.ground_points = ground.inliers;
    if (ground.found && ground.inliers >= o.min_points)
        r.ground_z_mm = ground.heightAt((r.x_min_mm + r.x_max_mm) / 2, r.range_mm);
    r.stands_on_ground = front.v_cells.min_mm <= g.ground_band_mm + 2 * g.cell_mm;
    if (r.stands_on_ground)
        r.z_bottom_mm = std::isfinite(r.ground_z_mm) ? r.ground_z_mm : 0.0; // 0: the ground of the ground frame
    else
        r.z_bottom_mm = front.v.min_mm;
    r.height_mm = r.z_top_mm - r.z_bottom_mm;
    r.registered = true;
    return r;
}

} // namespace binocle::method
