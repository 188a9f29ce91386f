// SPDX-License-Identifier: MIT
// Density grids of the paper's program (METHOD.md, Fig. 2b): a ground-frame cloud binned
// into top (XY), front (XZ) and side (YZ) views of point counts, and the solid objects
// localised in them.
#pragma once

#include "method/cloud_view.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace binocle::method {

// How a cloud is binned, and when a cell counts as occupied.
struct GridSpec {
    double cell_mm = 100;              // square cells, every view
    Extent x{-6000, 6000};             // lateral extent of the grids
    Extent y{0, 25000};                // range extent
    Extent z{-500, 4500};              // height extent
    int density_threshold = 3;         // points per cell for a cell to be occupied
    double ground_band_mm = 200;       // points lower than this (Z) are the ground, not objects
    int min_object_cells = 3;          // occupied regions with fewer cells are noise

    // Throws std::invalid_argument naming the member, its value and what was expected.
    void validate() const;
};

enum class View { Top, Front, Side };
const char *viewName(View view);     // "top", "front", "side"
const char *viewAxes(View view);     // "XY", "XZ", "YZ"

// One view: counts of points per cell. The picture's horizontal axis is u, its vertical
// axis v (top: u = X, v = Y; front: u = X, v = Z; side: u = Y, v = Z). counts is CV_32S
// with column = floor((u - u.min) / cell) and row = floor((v - v.min) / cell): row 0 is
// the lowest v (the bottom of the picture once drawn).
struct DensityView {
    View view = View::Top;
    double cell_mm = 100;
    Extent u, v;
    cv::Mat counts;

    int cols() const { return counts.cols; }
    int rows() const { return counts.rows; }
    int colOf(double u_mm) const; // -1 outside
    int rowOf(double v_mm) const; // -1 outside
    double uLow(int col) const { return u.min_mm + col * cell_mm; }
    double vLow(int row) const { return v.min_mm + row * cell_mm; }
    int count(int row, int col) const { return counts.at<int32_t>(row, col); }
    int64_t total() const;
    int maxCount() const;
    // CV_8U, 255 where count >= threshold.
    cv::Mat occupied(int threshold) const;
};

// Which points take part: nullptr (all) or a predicate on (X, Y, Z) in mm.
using PointFilter = std::function<bool(float x, float y, float z)>;

// Bins the finite points of `cloud` that fall inside spec's extents into one view.
DensityView binView(const CloudView &cloud, View view, const GridSpec &spec, const PointFilter &filter = nullptr);

struct DensityGrids {
    GridSpec spec;
    DensityView top, front, side;
};
// The three views of the whole cloud (ground included), as the paper's program showed them.
DensityGrids binCloud(const CloudView &cloud, const GridSpec &spec, const PointFilter &filter = nullptr);
// Points that are not ground: Z >= spec.ground_band_mm.
PointFilter aboveGround(const GridSpec &spec);

// A solid object localised in the top view: a connected region (8-neighbours) of
// occupied cells of the points above the ground band.
struct LocalisedObject {
    int id = 0;                              // 1, 2 ... by decreasing number of points
    int cells = 0;                           // occupied top-view cells of the region
    int64_t points = 0;                      // points in the region and the cells next to it
    double centroid_x_mm = 0, centroid_y_mm = 0; // mean of its points (top view)
    // Extents: 1st to 99th percentile of its points (README: why not sub-cell edges).
    double x_min_mm = 0, x_max_mm = 0;       // lateral
    double y_min_mm = 0, y_max_mm = 0;       // range
    double z_min_mm = 0, z_max_mm = 0;       // height
    double range_mm = 0;                     // median Y of its points: the face the camera sees
    double center_x_mm = 0;                  // middle of the lateral extent
    double width_mm = 0, depth_mm = 0;       // X and Y extents
    double height_mm = 0;                    // z_max, or z_max - z_min when it floats (README)
    bool on_ground = false;                  // its lower extent is within a cell of the ground band
};

// Localises the solid objects of a ground-frame cloud (METHOD.md "pipeline of the
// paper's program"): top view of the points above the ground band, occupied cells,
// connected regions of at least spec.min_object_cells cells; each with position and size.
std::vector<LocalisedObject> localiseObjects(const CloudView &cloud, const GridSpec &spec);

// [{"id":1,"x_mm":...,...}, ...] (mm), for a report_text.
std::string objectsJson(const std::vector<LocalisedObject> &objects);

// ---- Building blocks, shared with the panel reading (panel.hpp) ---------------------

// Extent of a set of points in one plane (u, v) read from a density grid of its own:
// cells with >= threshold points, regions smaller than min_cells dropped, then sub-cell
// edges (refineEdges). `members` flags the points in the kept cells or next to them.
struct PlanarExtent {
    bool found = false;
    Extent u, v;              // refined edges, mm
    Extent u_cells, v_cells;  // edges of the occupied cells, mm
    std::vector<uint8_t> members;
    int64_t member_count = 0;
};
PlanarExtent planarExtent(const std::vector<float> &u, const std::vector<float> &v, double cell_mm, int threshold,
                          int min_cells);

// Sub-cell edges of a run of occupied cells [lo, hi) (mm, on the cell lattice) from the
// coordinates of the points in and next to it. Each edge moves to where a sharp edge,
// with the point density of the (up to three) cells inside the outermost one, would
// leave as many points beyond the outermost cell's inner side as there are (an
// area-equivalent edge: symmetric noise does not move it). Runs shorter than 3 cells
// keep their cell edges.
Extent refineEdges(const std::vector<float> &values, Extent cells, double cell_mm);

// Median of the values (NaN when empty); reorders a copy.
double median(std::vector<float> values);
// Percentile (0-100, linear between ranks) of the values (NaN when empty).
double percentile(std::vector<float> values, double percent);

} // namespace binocle::method
