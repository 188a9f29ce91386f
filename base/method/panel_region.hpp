// SPDX-License-Identifier: MIT
// Which points of the panel's range band are the panel: the region of dense front-view
// cells connected to the panel's stated position, split from clutter at a density edge
// (README.md beside this file: "Reading X', Y', Z' of the E1 panel").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace binocle::method {

struct PanelRegionOptions {
    double cell_mm = 100;            // front-view cell
    int density_threshold = 3;       // the grid's threshold: the least a cell needs, whatever the panel
    int min_cells = 3;               // smaller dense specks are noise
    double seed_x_mm = 0;            // the panel's stated lateral position (its middle)
    double seed_half_width_mm = 1000; // the panel has points within this of seed_x_mm
    double relative_density = 0.5;   // a cell is the panel's when it holds this share of the panel's typical cell
    double bridge_mm = 500;          // gaps up to this wide inside the panel are bridged (the E1 panel's column gap)
};

struct PanelRegion {
    bool found = false;
    std::string reason;             // why not, when not found
    int threshold = 0;              // points per cell the panel's cells needed (density edge)
    double reference_count = 0;     // the panel's typical cell (75th percentile at the stated position)
    std::vector<uint8_t> members;   // per input point: in the region (its cells or next to them)
    int64_t member_count = 0;
};

// x, z: the front-view coordinates (mm) of the band's points above the ground.
PanelRegion selectPanelRegion(const std::vector<float> &x, const std::vector<float> &z, const PanelRegionOptions &o);

} // namespace binocle::method
