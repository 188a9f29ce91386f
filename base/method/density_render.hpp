// SPDX-License-Identifier: MIT
// Density views drawn as pictures a person can read: cells coloured by point count (log
// scale), axes in metres with ticks, a title, a colour scale and optional boxes.
#pragma once

#include "method/density_grid.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <string>
#include <vector>

namespace binocle::method {

// A box drawn over a view, in the view's (u, v) millimetres, e.g. a localised object;
// with `cells`, also the outline of those cells (what a reading took, e.g. the panel's).
struct ViewOverlay {
    Extent u, v;
    std::string label;
    cv::Scalar color{40, 40, 220}; // BGR
    std::vector<std::array<float, 2>> cells; // lower corners (u, v) in mm, each cell_mm square
    double cell_mm = 0;
};

struct RenderOptions {
    std::string title;          // empty: "<Top|Front|Side> view (XY) - N points, cell C mm"
    int density_threshold = 0;  // > 0: cells below it drawn pale, and the value marked on the scale
    int target_size_px = 640;   // longer side of the plot area (cells are whole pixel squares)
    std::vector<ViewOverlay> overlays;
};

// A BGR8 picture of the view: white background, cells coloured by log(1 + count)
// (viridis), the ground frame's axes in metres, the camera's position in the top view.
cv::Mat renderDensityView(const DensityView &view, const RenderOptions &options = {});

// Writes a PNG whole or not at all (a temporary file in the same folder, then rename).
// Throws std::runtime_error naming the path.
void writePngAtomic(const std::string &path, const cv::Mat &image);

} // namespace binocle::method
