// SPDX-License-Identifier: MIT
// Reads the measured width X', range Y' and height Z' of the E1 test panel from a
// ground-frame cloud, automatically (method: README.md beside this file).
#pragma once

#include "method/cloud_view.hpp"
#include "method/density_grid.hpp"
#include "method/relative_errors.hpp"

#include <cstdint>
#include <string>

namespace binocle::method {

struct PanelReadingOptions {
    GridSpec grid;                      // cell size, density threshold, ground band, extents
    double expected_range_mm = 0;       // true range Y of the panel's face; <= 0: search all of grid.y
    double range_search_percent = 30;   // the panel's band is looked for within Y +- this % of Y
    double range_margin_mm = 500;       // half-depth of the range band the panel is read in
    Extent lateral;                     // lateral window; not valid() (the default): grid.x
    int64_t min_points = 50;            // fewer panel points: not registered
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

    PanelReading();
    PanelSize size() const { return {width_mm, range_mm, height_mm}; }
};

// Reads X', Y', Z'. Never throws for a cloud without a panel: that is a reading with
// registered = false and a reason (a rejected configuration). Throws std::invalid_argument
// for invalid options.
PanelReading readPanel(const CloudView &cloud, const PanelReadingOptions &options);

} // namespace binocle::method
