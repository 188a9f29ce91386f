// SPDX-License-Identifier: MIT
// X', Y', Z' of the E1 test panel, read from the density grids (README.md: the method).
#include "method/panel.hpp"

#include "method/ground_plane.hpp"
#include "method/panel_region.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
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

namespace {
// The points of the window (inside the grid and the lateral window, finite).
struct Window {
    const CloudView &cloud;
    const GridSpec &g;
    Extent lateral;
    bool contains(size_t i) const {
        return cloud.finite(i) && lateral.contains(cloud.x(i)) && g.x.contains(cloud.x(i)) && g.y.contains(cloud.y(i)) &&
               g.z.contains(cloud.z(i));
    }
};

// Step 1: the range band. The densest band of points above the ground near the expected
// range (at the stated lateral position for the region reading), centred on the median
// range of what it holds; the region reading then narrows it to the panel's own depth
// spread, so that a matcher's smear behind or in front of the panel (a depth step in
// the top view) stays out. Returns false with r.reason when too few points.
bool findBand(const Window &w, const PanelReadingOptions &o, Extent search, PanelReading &r) {
    const GridSpec &g = w.g;
    const bool region = o.method == PanelReadingMethod::Region;
    Extent seed = w.lateral;
    if (region)
        seed = {std::max(seed.min_mm, o.expected_x_mm - o.seed_half_width_mm),
                std::min(seed.max_mm, o.expected_x_mm + o.seed_half_width_mm)};
    std::vector<float> ys;
    for (size_t i = 0; i < w.cloud.count; ++i)
        if (w.contains(i) && seed.contains(w.cloud.x(i)) && w.cloud.z(i) >= g.ground_band_mm &&
            w.cloud.y(i) >= search.min_mm - o.range_margin_mm && w.cloud.y(i) < search.max_mm + o.range_margin_mm)
            ys.push_back(w.cloud.y(i));
    const auto [centre, inBand] = densestBand(ys, search, o.range_margin_mm, g.cell_mm);
    if (inBand < o.min_points) {
        r.reason = "no panel: " + std::to_string(inBand) + " points above the ground in the densest range band of " +
                   mm(2 * o.range_margin_mm) + " between " + mm(search.min_mm) + " and " + mm(search.max_mm) +
                   (region ? " within " + mm(o.seed_half_width_mm) + " of the stated lateral position " + mm(o.expected_x_mm)
                           : std::string()) +
                   " (at least " + std::to_string(o.min_points) + " expected)";
        return false;
    }
    std::vector<float> inside;
    for (float y : ys)
        if (y >= centre - o.range_margin_mm && y <= centre + o.range_margin_mm) inside.push_back(y);
    const double centred = median(inside);
    double half = o.range_margin_mm;
    if (region) {
        std::vector<float> deviation;
        deviation.reserve(inside.size());
        for (float y : inside) deviation.push_back(static_cast<float>(std::abs(y - centred)));
        half = std::clamp(4 * median(deviation), g.cell_mm, o.range_margin_mm);
    }
    r.band = {centred - half, centred + half};
    return true;
}

// The cells (lower corners) of a plane holding at least `threshold` of the points.
std::vector<std::array<float, 2>> cellsOf(const std::vector<float> &u, const std::vector<float> &v,
                                          const std::vector<uint8_t> &keep, double cell, int threshold) {
    std::map<std::pair<int64_t, int64_t>, int> counts;
    for (size_t i = 0; i < u.size(); ++i)
        if (keep[i]) ++counts[{static_cast<int64_t>(std::floor(u[i] / cell)), static_cast<int64_t>(std::floor(v[i] / cell))}];
    std::vector<std::array<float, 2>> out;
    for (const auto &[c, n] : counts)
        if (n >= threshold)
            out.push_back({static_cast<float>(static_cast<double>(c.first) * cell),
                           static_cast<float>(static_cast<double>(c.second) * cell)});
    return out;
}
// Step 2 of the region reading: keeps, of the band's points, the panel's region
// (panel_region.hpp); false with r.reason when there is none.
bool keepPanelRegion(const PanelReadingOptions &o, std::vector<float> &px, std::vector<float> &py,
                     std::vector<float> &pz, PanelReading &r) {
    const GridSpec &g = o.grid;
    PanelRegionOptions ro;
    ro.cell_mm = g.cell_mm;
    ro.density_threshold = g.density_threshold;
    ro.min_cells = g.min_object_cells;
    ro.seed_x_mm = o.expected_x_mm;
    ro.seed_half_width_mm = o.seed_half_width_mm;
    ro.relative_density = o.relative_density;
    ro.bridge_mm = o.bridge_mm;
    const PanelRegion found = selectPanelRegion(px, pz, ro);
    if (!found.found) {
        r.reason = "no panel: " + found.reason + " in the range band " + mm(r.band.min_mm) + " .. " + mm(r.band.max_mm);
        return false;
    }
    r.cell_threshold = found.threshold;
    size_t k = 0;
    for (size_t i = 0; i < px.size(); ++i)
        if (found.members[i]) {
            px[k] = px[i];
            py[k] = py[i];
            pz[k] = pz[i];
            ++k;
        }
    px.resize(k);
    py.resize(k);
    pz.resize(k);
    return true;
}
} // namespace

PanelReading readPanel(const CloudView &cloud, const PanelReadingOptions &o) {
    const GridSpec &g = o.grid;
    g.validate();
    if (!(o.range_margin_mm > 0)) throw std::invalid_argument("range margin " + mm(o.range_margin_mm) + ": expected > 0");
    if (!(o.range_search_percent >= 0))
        throw std::invalid_argument("range search " + std::to_string(o.range_search_percent) + " %: expected >= 0");
    const bool region = o.method == PanelReadingMethod::Region;
    if (region && !(o.seed_half_width_mm > 0 && o.relative_density >= 0 && o.relative_density <= 1 && o.bridge_mm >= 0 &&
                    std::isfinite(o.expected_x_mm) && o.max_width_ratio > 1))
        throw std::invalid_argument("panel region options: seed half width " + mm(o.seed_half_width_mm) +
                                    " (expected > 0), relative density " + std::to_string(o.relative_density) +
                                    " (expected 0..1), bridge " + mm(o.bridge_mm) + " (expected >= 0), width ratio " +
                                    std::to_string(o.max_width_ratio) + " (expected > 1)");
    const Window w{cloud, g, o.lateral.valid() ? o.lateral : g.x};
    Extent search = g.y;
    if (o.expected_range_mm > 0) {
        const double s = o.expected_range_mm * o.range_search_percent / 100.0;
        search = {std::max(g.y.min_mm, o.expected_range_mm - s), std::min(g.y.max_mm, o.expected_range_mm + s)};
        if (!search.valid()) search = {o.expected_range_mm - 1, o.expected_range_mm + 1}; // outside the grid
    }

    PanelReading r;
    if (!findBand(w, o, search, r)) return r;

    // 2. The band's points above the ground, and the panel's among them: the region of
    // dense front-view cells connected to the stated position (or, read the old way,
    // every occupied cell of the band).
    std::vector<float> px, py, pz;
    for (size_t i = 0; i < cloud.count; ++i) {
        if (!w.contains(i) || !r.band.contains(cloud.y(i)) || cloud.z(i) < g.ground_band_mm) continue;
        px.push_back(cloud.x(i));
        py.push_back(cloud.y(i));
        pz.push_back(cloud.z(i));
    }
    r.cell_threshold = g.density_threshold;
    if (region && !keepPanelRegion(o, px, py, pz, r)) return r;
    const PlanarExtent front = planarExtent(px, pz, g.cell_mm, r.cell_threshold, g.min_object_cells);
    if (!front.found || front.member_count < o.min_points) {
        r.reason = "no panel: " + std::to_string(front.member_count) + " points in occupied front-view cells (" +
                   std::to_string(r.cell_threshold) + " or more points per " + mm(g.cell_mm) +
                   " cell) in the range band " + mm(r.band.min_mm) + " .. " + mm(r.band.max_mm) + " (at least " +
                   std::to_string(o.min_points) + " expected)";
        return r;
    }
    std::vector<float> panelY;
    panelY.reserve(static_cast<size_t>(front.member_count));
    for (size_t i = 0; i < py.size(); ++i)
        if (front.members[i]) panelY.push_back(py[i]);
    r.points = front.member_count;
    r.front_cells = cellsOf(px, pz, front.members, g.cell_mm, r.cell_threshold);
    r.top_cells = cellsOf(px, py, front.members, g.cell_mm, r.cell_threshold);

    // 3. X' from the front view's lateral edges, Y' the median range of the panel's points.
    r.x_min_mm = front.u.min_mm;
    r.x_max_mm = front.u.max_mm;
    r.width_mm = r.x_max_mm - r.x_min_mm;
    r.range_mm = median(panelY);
    if (region && o.expected_width_mm > 0 && r.width_mm > o.max_width_ratio * o.expected_width_mm) {
        r.reason = "panel not separated from its surroundings: the region connected to the stated position is " +
                   mm(r.width_mm) + " wide (" + mm(r.x_min_mm) + " .. " + mm(r.x_max_mm) + "), more than " +
                   std::to_string(o.max_width_ratio).substr(0, 4) + " times the stated width " + mm(o.expected_width_mm);
        r.width_mm = r.range_mm = kNaN;
        return r;
    }

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
