// SPDX-License-Identifier: MIT
// Reads the measured width X', range Y' and height Z' of the E1 test panel from a
// ground-frame cloud, automatically (method: README.md beside this file).
#pragma once

#include "method/cloud_view.hpp"
#include "method/density_grid.hpp"
#include "method/relative_errors.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace binocle::method {

// How the panel is told from the rest of its range band (README.md beside this file).
enum class PanelReadingMethod {
    Region, // the region of dense cells connected to the stated position (a person's reading; default)
    Band,   // every occupied cell across the band (the reading before issue 33; for comparison)
};

struct PanelReadingOptions {
    GridSpec grid;                      // cell size, density threshold, ground band, extents
    double expected_range_mm = 0;       // true range Y of the panel's face; <= 0: search all of grid.y
    double range_search_percent = 30;   // the panel's band is looked for within Y +- this % of Y
    double range_margin_mm = 500;       // half-depth of the range band the panel is read in (at most)
    Extent lateral;                     // lateral window; not valid() (the default): grid.x
    int64_t min_points = 50;            // fewer panel points: not registered
    PanelReadingMethod method = PanelReadingMethod::Region;
    // Region reading: where the panel stands (rough) and how it is told from clutter.
    double expected_x_mm = 0;           // its stated lateral middle (0: in front of the rig)
    double seed_half_width_mm = 1000;   // the panel has points within this of expected_x_mm
    double relative_density = 0.5;      // its cells hold at least this share of its typical cell
    double bridge_mm = 500;             // gaps inside the panel up to this wide are bridged
    double expected_width_mm = 0;       // > 0: a region wider than max_width_ratio times this is
    double max_width_ratio = 2;         //      not separated from its clutter: not registered
};

struct PanelReading {
    bool registered = false;
    std::string reason;                  // why not, when not registered
    double width_mm, range_mm, height_mm; // X', Y', Z' (NaN when not registered)
    double x_min_mm, x_max_mm;           // lateral edges
    double z_bottom_mm, z_top_mm;        // lower and upper edges
    double ground_z_mm;                  // the fitted ground's height under the panel (NaN: no ground)
    bool stands_on_ground = false;       // its lowest occupied cells touch the ground band
    Extent band;                         // range band the panel was read in
    int64_t points = 0;                  // points of the panel (above the ground band)
    int64_t ground_points = 0;           // inliers of the fitted ground plane
    int cell_threshold = 0;              // points per cell the panel's cells needed
    // The cells read as the panel (lower corners, mm; side grid.cell_mm), for drawing:
    // front view (X, Z) and top view (X, Y).
    std::vector<std::array<float, 2>> front_cells, top_cells;

    PanelReading();
    PanelSize size() const { return {width_mm, range_mm, height_mm}; }
};

// Reads X', Y', Z'. Never throws for a cloud without a panel: that is a reading with
// registered = false and a reason (a rejected configuration). Throws std::invalid_argument
// for invalid options.
PanelReading readPanel(const CloudView &cloud, const PanelReadingOptions &options);

} // namespace binocle::method
