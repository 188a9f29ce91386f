// SPDX-License-Identifier: MIT
// Density grids (top, front, side views) and the solid objects localised in them.
#include "method/density_grid.hpp"

#include <nlohmann/json.hpp>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace binocle::method {

namespace {

std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

void checkExtent(const Extent &e, const char *name) {
    if (!e.valid())
        throw std::invalid_argument(std::string("grid ") + name + " extent [" + number(e.min_mm) + ", " +
                                    number(e.max_mm) + "] mm: expected finite bounds with min < max");
}

// Cells of one view at most, checked before any grid is allocated (8000 x 8000).
constexpr double kMaxViewCells = 64e6;

int cellsAlong(const Extent &e, double cell) { return static_cast<int>(std::ceil(e.size() / cell - 1e-9)); }

// u and v of a point in a view.
inline void project(View view, float x, float y, float z, double &u, double &v) {
    switch (view) {
    case View::Top: u = x; v = y; break;
    case View::Front: u = x; v = z; break;
    case View::Side: u = y; v = z; break;
    }
}

} // namespace

void GridSpec::validate() const {
    if (!(cell_mm > 0) || !std::isfinite(cell_mm))
        throw std::invalid_argument("cell size " + number(cell_mm) + " mm: expected a positive number");
    checkExtent(x, "X");
    checkExtent(y, "Y");
    checkExtent(z, "Z");
    // A cell larger than an extent leaves that axis without a cell (1e300 mm: 0 cells, and
    // every view an empty image).
    for (const auto &[e, name] : {std::pair<const Extent *, const char *>{&x, "X"}, {&y, "Y"}, {&z, "Z"}})
        if (cell_mm > e->size())
            throw std::invalid_argument("cell size " + number(cell_mm) + " mm is larger than the grid's " + name + " extent (" +
                                        number(e->size()) + " mm): expected a cell no larger than the smallest extent");
    // Counted in doubles before any cast to int (4.3e11 mm / 100 mm overflows an int), for
    // each of the three views: every axis has at least one cell, so each count bounds its
    // axes too.
    auto along = [&](const Extent &e) { return std::ceil(e.size() / cell_mm - 1e-9); };
    const double nx = along(x), ny = along(y), nz = along(z);
    const struct {
        const char *view;
        double cells;
    } views[] = {{"top-view (X by Y)", nx * ny}, {"front-view (X by Z)", nx * nz}, {"side-view (Y by Z)", ny * nz}};
    for (const auto &v : views)
        if (!(v.cells <= kMaxViewCells))
            throw std::invalid_argument("cell size " + number(cell_mm) + " mm over the grid's extent (X [" + number(x.min_mm) +
                                        ", " + number(x.max_mm) + "], Y [" + number(y.min_mm) + ", " + number(y.max_mm) +
                                        "], Z [" + number(z.min_mm) + ", " + number(z.max_mm) + "] mm) gives " +
                                        number(v.cells) + " " + v.view + " cells: expected at most " +
                                        number(kMaxViewCells) + " (a larger cell or a smaller extent)");
    if (density_threshold < 1)
        throw std::invalid_argument("density threshold " + std::to_string(density_threshold) +
                                    ": expected at least 1 point per cell");
    if (min_object_cells < 1)
        throw std::invalid_argument("minimum object size " + std::to_string(min_object_cells) +
                                    " cells: expected at least 1");
    if (!std::isfinite(ground_band_mm))
        throw std::invalid_argument("ground band " + number(ground_band_mm) + " mm: expected a finite number");
}

namespace {
// Each view's name and the two axes of the ground frame it shows.
struct ViewLabels {
    const char *name, *axes;
};
ViewLabels viewLabels(View view) {
    switch (view) {
    case View::Top: return {"top", "XY"};
    case View::Front: return {"front", "XZ"};
    case View::Side: return {"side", "YZ"};
    }
    return {"?", "?"};
}
} // namespace

const char *viewName(View view) { return viewLabels(view).name; }

const char *viewAxes(View view) { return viewLabels(view).axes; }

int DensityView::colOf(double u_mm) const {
    if (!u.contains(u_mm)) return -1;
    const int c = static_cast<int>(std::floor((u_mm - u.min_mm) / cell_mm));
    return c < cols() ? c : -1;
}

int DensityView::rowOf(double v_mm) const {
    if (!v.contains(v_mm)) return -1;
    const int r = static_cast<int>(std::floor((v_mm - v.min_mm) / cell_mm));
    return r < rows() ? r : -1;
}

int64_t DensityView::total() const {
    int64_t sum = 0;
    for (int r = 0; r < rows(); ++r)
        for (int c = 0; c < cols(); ++c) sum += count(r, c);
    return sum;
}

int DensityView::maxCount() const {
    if (counts.empty()) return 0;
    double mx = 0;
    cv::minMaxLoc(counts, nullptr, &mx);
    return static_cast<int>(mx);
}

cv::Mat DensityView::occupied(int threshold) const {
    cv::Mat occ;
    cv::compare(counts, threshold, occ, cv::CMP_GE);
    return occ;
}

DensityView binView(const CloudView &cloud, View view, const GridSpec &spec, const PointFilter &filter) {
    spec.validate();
    DensityView d;
    d.view = view;
    d.cell_mm = spec.cell_mm;
    d.u = view == View::Side ? spec.y : spec.x;
    d.v = view == View::Top ? spec.y : spec.z;
    d.counts = cv::Mat::zeros(cellsAlong(d.v, spec.cell_mm), cellsAlong(d.u, spec.cell_mm), CV_32S);
    for (size_t i = 0; i < cloud.count; ++i) {
        if (!cloud.finite(i)) continue;
        const float x = cloud.x(i), y = cloud.y(i), z = cloud.z(i);
        // Every view counts the same points: those inside all three extents.
        if (!spec.x.contains(x) || !spec.y.contains(y) || !spec.z.contains(z)) continue;
        if (filter && !filter(x, y, z)) continue;
        double u = 0, v = 0;
        project(view, x, y, z, u, v);
        const int c = d.colOf(u), r = d.rowOf(v);
        if (c >= 0 && r >= 0) ++d.counts.at<int32_t>(r, c);
    }
    return d;
}

DensityGrids binCloud(const CloudView &cloud, const GridSpec &spec, const PointFilter &filter) {
    DensityGrids g;
    g.spec = spec;
    g.top = binView(cloud, View::Top, spec, filter);
    g.front = binView(cloud, View::Front, spec, filter);
    g.side = binView(cloud, View::Side, spec, filter);
    return g;
}

PointFilter aboveGround(const GridSpec &spec) {
    const double band = spec.ground_band_mm;
    return [band](float, float, float z) { return z >= band; };
}

double median(std::vector<float> values) {
    if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
    const size_t mid = values.size() / 2;
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
    double m = values[mid];
    if (values.size() % 2 == 0) {
        const float below = *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid));
        m = (m + below) / 2.0;
    }
    return m;
}

double percentile(std::vector<float> values, double percent) {
    if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
    const double pos = std::clamp(percent, 0.0, 100.0) / 100.0 * static_cast<double>(values.size() - 1);
    const size_t k = static_cast<size_t>(pos);
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
    const double lo = values[k];
    if (k + 1 >= values.size()) return lo;
    const double hi = *std::min_element(values.begin() + static_cast<std::ptrdiff_t>(k) + 1, values.end());
    return lo + (hi - lo) * (pos - static_cast<double>(k));
}

Extent refineEdges(const std::vector<float> &values, Extent cells, double cell) {
    const int run = static_cast<int>(std::lround(cells.size() / cell));
    if (run < 3) return cells;
    // The density inside comes from up to three cells next to the outermost one.
    const int k = std::min(3, run - 2);
    auto countIn = [&](double lo, double hi) {
        int64_t n = 0;
        for (float v : values)
            if (v >= lo && v < hi) ++n;
        return n;
    };
    Extent e = cells;
    {
        const double ref = cells.min_mm + cell;
        const int64_t inside = countIn(ref, ref + k * cell);
        if (inside > 0) {
            const double outside = static_cast<double>(countIn(cells.min_mm - cell, ref));
            e.min_mm = std::clamp(ref - outside * k * cell / static_cast<double>(inside), cells.min_mm - cell, ref);
        }
    }
    {
        const double ref = cells.max_mm - cell;
        const int64_t inside = countIn(ref - k * cell, ref);
        if (inside > 0) {
            const double outside = static_cast<double>(countIn(ref, cells.max_mm + cell));
            e.max_mm = std::clamp(ref + outside * k * cell / static_cast<double>(inside), ref, cells.max_mm + cell);
        }
    }
    return e;
}

PlanarExtent planarExtent(const std::vector<float> &u, const std::vector<float> &v, double cell, int threshold,
                          int min_cells) {
    PlanarExtent out;
    out.members.assign(u.size(), 0);
    if (u.empty() || u.size() != v.size() || !(cell > 0)) return out;
    const auto [umin, umax] = std::minmax_element(u.begin(), u.end());
    const auto [vmin, vmax] = std::minmax_element(v.begin(), v.end());
    // One empty cell all round, so that dilation and edges never leave the grid.
    const double u0 = (std::floor(*umin / cell) - 1) * cell, v0 = (std::floor(*vmin / cell) - 1) * cell;
    const int cols = static_cast<int>(std::floor((*umax - u0) / cell)) + 2;
    const int rows = static_cast<int>(std::floor((*vmax - v0) / cell)) + 2;
    if (static_cast<double>(cols) * rows > 64e6)
        throw std::invalid_argument("planar extent: " + std::to_string(cols) + " x " + std::to_string(rows) +
                                    " cells of " + number(cell) + " mm: expected a bounded set of points");
    cv::Mat counts = cv::Mat::zeros(rows, cols, CV_32S);
    std::vector<cv::Point> cellOf(u.size());
    for (size_t i = 0; i < u.size(); ++i) {
        cellOf[i] = {static_cast<int>(std::floor((u[i] - u0) / cell)), static_cast<int>(std::floor((v[i] - v0) / cell))};
        ++counts.at<int32_t>(cellOf[i]);
    }
    cv::Mat occ, labels, stats, centroids;
    cv::compare(counts, threshold, occ, cv::CMP_GE);
    const int n = cv::connectedComponentsWithStats(occ, labels, stats, centroids, 8, CV_32S);
    cv::Mat keep = cv::Mat::zeros(rows, cols, CV_8U);
    int c0 = cols, c1 = -1, r0 = rows, r1 = -1;
    for (int l = 1; l < n; ++l) {
        if (stats.at<int>(l, cv::CC_STAT_AREA) < min_cells) continue;
        keep.setTo(255, labels == l);
        c0 = std::min(c0, stats.at<int>(l, cv::CC_STAT_LEFT));
        r0 = std::min(r0, stats.at<int>(l, cv::CC_STAT_TOP));
        c1 = std::max(c1, stats.at<int>(l, cv::CC_STAT_LEFT) + stats.at<int>(l, cv::CC_STAT_WIDTH));
        r1 = std::max(r1, stats.at<int>(l, cv::CC_STAT_TOP) + stats.at<int>(l, cv::CC_STAT_HEIGHT));
    }
    if (c1 < 0) return out;
    cv::Mat near;
    cv::dilate(keep, near, cv::Mat::ones(3, 3, CV_8U));
    std::vector<float> mu, mv;
    for (size_t i = 0; i < u.size(); ++i) {
        if (!near.at<uint8_t>(cellOf[i])) continue;
        out.members[i] = 1;
        ++out.member_count;
        mu.push_back(u[i]);
        mv.push_back(v[i]);
    }
    out.found = true;
    out.u_cells = {u0 + c0 * cell, u0 + c1 * cell};
    out.v_cells = {v0 + r0 * cell, v0 + r1 * cell};
    out.u = refineEdges(mu, out.u_cells, cell);
    out.v = refineEdges(mv, out.v_cells, cell);
    return out;
}

std::vector<LocalisedObject> localiseObjects(const CloudView &cloud, const GridSpec &spec) {
    const PointFilter above = aboveGround(spec);
    const DensityView top = binView(cloud, View::Top, spec, above);
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(top.occupied(spec.density_threshold), labels, stats, centroids, 8,
                                                   CV_32S);
    std::vector<int> objectOfLabel(static_cast<size_t>(n), -1);
    std::vector<LocalisedObject> objects;
    for (int l = 1; l < n; ++l) {
        if (stats.at<int>(l, cv::CC_STAT_AREA) < spec.min_object_cells) continue;
        objectOfLabel[static_cast<size_t>(l)] = static_cast<int>(objects.size());
        LocalisedObject o;
        o.cells = stats.at<int>(l, cv::CC_STAT_AREA);
        const int c = stats.at<int>(l, cv::CC_STAT_LEFT), r = stats.at<int>(l, cv::CC_STAT_TOP);
        o.x_min_mm = top.uLow(c);
        o.x_max_mm = top.uLow(c + stats.at<int>(l, cv::CC_STAT_WIDTH));
        o.y_min_mm = top.vLow(r);
        o.y_max_mm = top.vLow(r + stats.at<int>(l, cv::CC_STAT_HEIGHT));
        objects.push_back(o);
    }
    // The points of each region: in its cells, or in a cell next to them (edges that
    // stayed under the threshold belong to the object they touch).
    struct Points { std::vector<float> x, y, z; };
    std::vector<Points> pts(objects.size());
    for (size_t i = 0; i < cloud.count; ++i) {
        if (!cloud.finite(i)) continue;
        const float x = cloud.x(i), y = cloud.y(i), z = cloud.z(i);
        if (!spec.x.contains(x) || !spec.y.contains(y) || !spec.z.contains(z) || !above(x, y, z)) continue;
        const int c = top.colOf(x), r = top.rowOf(y);
        if (c < 0 || r < 0) continue;
        int object = objectOfLabel[static_cast<size_t>(labels.at<int32_t>(r, c))];
        for (int dr = -1; dr <= 1 && object < 0; ++dr)
            for (int dc = -1; dc <= 1 && object < 0; ++dc) {
                const int rr = r + dr, cc = c + dc;
                if (rr < 0 || cc < 0 || rr >= top.rows() || cc >= top.cols()) continue;
                object = objectOfLabel[static_cast<size_t>(labels.at<int32_t>(rr, cc))];
            }
        if (object < 0) continue;
        Points &p = pts[static_cast<size_t>(object)];
        p.x.push_back(x);
        p.y.push_back(y);
        p.z.push_back(z);
    }
    for (size_t k = 0; k < objects.size(); ++k) {
        LocalisedObject &o = objects[k];
        const Points &p = pts[k];
        o.points = static_cast<int64_t>(p.x.size());
        if (p.x.empty()) continue;
        double sx = 0, sy = 0;
        for (size_t i = 0; i < p.x.size(); ++i) {
            sx += p.x[i];
            sy += p.y[i];
        }
        o.centroid_x_mm = sx / static_cast<double>(p.x.size());
        o.centroid_y_mm = sy / static_cast<double>(p.y.size());
        // Objects show faces of very different point densities (a front face, a top or
        // a side seen at a grazing angle): area-equivalent edges do not hold there, so
        // each extent is the 1st to 99th percentile of the points, within one cell of
        // the region's cells.
        o.x_min_mm = std::max(o.x_min_mm - spec.cell_mm, percentile(p.x, 1));
        o.x_max_mm = std::min(o.x_max_mm + spec.cell_mm, percentile(p.x, 99));
        o.y_min_mm = std::max(o.y_min_mm - spec.cell_mm, percentile(p.y, 1));
        o.y_max_mm = std::min(o.y_max_mm + spec.cell_mm, percentile(p.y, 99));
        o.z_min_mm = percentile(p.z, 1);
        o.z_max_mm = percentile(p.z, 99);
        o.on_ground = o.z_min_mm <= spec.ground_band_mm + spec.cell_mm;
        o.range_mm = median(p.y);
        o.center_x_mm = (o.x_min_mm + o.x_max_mm) / 2;
        o.width_mm = o.x_max_mm - o.x_min_mm;
        o.depth_mm = o.y_max_mm - o.y_min_mm;
        o.height_mm = o.on_ground ? o.z_max_mm : o.z_max_mm - o.z_min_mm;
    }
    objects.erase(std::remove_if(objects.begin(), objects.end(), [](const LocalisedObject &o) { return o.points == 0; }),
                  objects.end());
    std::stable_sort(objects.begin(), objects.end(),
                     [](const LocalisedObject &a, const LocalisedObject &b) { return a.points > b.points; });
    for (size_t k = 0; k < objects.size(); ++k) objects[k].id = static_cast<int>(k) + 1;
    return objects;
}

std::string objectsJson(const std::vector<LocalisedObject> &objects) {
    // Millimetres to 0.1 mm: finer digits would only be noise of the grid.
    auto mm = [](double v) { return std::round(v * 10.0) / 10.0; };
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const LocalisedObject &o : objects) {
        list.push_back({{"id", o.id},
                        {"points", o.points},
                        {"cells", o.cells},
                        {"center_x_mm", mm(o.center_x_mm)},
                        {"range_mm", mm(o.range_mm)},
                        {"centroid_mm", {mm(o.centroid_x_mm), mm(o.centroid_y_mm)}},
                        {"x_mm", {mm(o.x_min_mm), mm(o.x_max_mm)}},
                        {"y_mm", {mm(o.y_min_mm), mm(o.y_max_mm)}},
                        {"z_mm", {mm(o.z_min_mm), mm(o.z_max_mm)}},
                        {"width_mm", mm(o.width_mm)},
                        {"depth_mm", mm(o.depth_mm)},
                        {"height_mm", mm(o.height_mm)},
                        {"on_ground", o.on_ground}});
    }
    return list.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

} // namespace binocle::method
