// SPDX-License-Identifier: MIT
// One frame as the viewer holds it (a deep copy of the pipeline's products), encoded as
// one WebSocket message for the page, or written as files for a snapshot.
#pragma once

#include "config/rig_config.hpp"
#include "method/density_grid.hpp"
#include "pipeline/pipeline.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace binocle::viewer {

// What the page shows of one frame; owns every byte (the pipeline may reuse its own).
struct FrameProducts {
    FrameResult result;             // images cloned, cloud copied
    nlohmann::ordered_json metrics; // {evaluator: {metric: value, text: "..."}}
    uint64_t frames_processed = 0;  // by the pipeline since the view started
    double pipeline_fps = 0;        // frames per second over the last frames
    std::pair<int32_t, int32_t> disparity_range{0, 0}; // the matcher's answer: min, count
    double focal_length_px = 0, baseline_mm = 0;
    std::string source_statistics;  // the source plugin's text, as it gave it
};

// Deep copy of what the pipeline lends for the duration of a callback.
FrameProducts copyFrame(const FrameResult &r);

// Top (above the ground band), front and side density views, with the boxes the
// evaluators reported (`view_overlays` texts), rendered at `target_px`.
std::vector<cv::Mat> renderDensityViews(const FrameProducts &p, const method::GridSpec &grid, int target_px);

// Disparity coloured with a fixed scale [lo, hi] px (OpenCV's TURBO map; invalid: black).
cv::Mat colorizeDisparityRange(const cv::Mat &disparity, double lo_px, double hi_px);
// The colour map's 256 entries as [[r, g, b], ...] for the page's colour scale.
nlohmann::ordered_json colorScale();

struct EncodeOptions {
    int jpeg_quality = 85;
    int view_px = 320;           // longer side of each density view
    size_t max_cloud_points = 20000; // the cloud is thinned evenly to at most this
    bool with_cloud = true;      // false: no `cloud` in the header, no cloud blobs (the
                                 // page keeps the last cloud it got)
    method::GridSpec grid;
};

// One binary message: a 4-byte little-endian header length, the header (JSON: figures,
// and `blobs`: [{name, type, offset, size}]), then the blobs: the JPEG images (left,
// right, disparity, top, front, side) and, when with_cloud, the cloud as float32 x, y, z
// in metres (`cloud_xyz`) and uint8 r, g, b (`cloud_rgb`, where the cloud has colours).
std::string encodeFrame(const FrameProducts &p, const EncodeOptions &options);

// Writes the frame's outputs as `binocle run` does (`outputs` of the rig), plus its
// density views (view_top|front|side_NNNNNN.png) and frame_NNNNNN.json (figures,
// metrics, the rig as run). Returns the paths written.
std::vector<std::string> writeSnapshot(const FrameProducts &p, const OutputOptions &outputs, const std::string &rigYaml,
                                       const method::GridSpec &grid, const std::string &dir);

} // namespace binocle::viewer
