// SPDX-License-Identifier: MIT
// What the paper evaluator learns from its input besides the cloud: the truth the
// source attaches to a frame (metadata YAML) and the head's geometry (rig YAML,
// calibration YAML).
#pragma once

#include "method/ground_plane.hpp"

#include <optional>
#include <string>
#include <vector>

namespace binocle::paper {

// The frame metadata of a simulated (or annotated) source; every member is optional.
struct FrameTruth {
    // `panel:` {width_mm, range_mm, height_mm, center_mm} (or size_mm + center_mm).
    std::optional<double> panel_width_mm, panel_range_mm, panel_height_mm;
    std::optional<double> panel_center_x_mm, panel_base_z_mm;
    // `rig:` of the sim source: the geometry the images were made with.
    std::optional<double> baseline_mm, focal_length_mm, pixel_pitch_um, focal_length_px;
    std::optional<double> camera_height_mm, inclination_deg;
    std::optional<int> image_width, image_height;
    std::string main_object;                      // `main_object:`
    std::vector<method::KnownObject> objects;     // `objects:` with center_mm and size_mm
};

// Parses metadata YAML (null or empty: nothing known). Throws sdk::Error naming the
// frame metadata and the key when a present key is malformed.
FrameTruth parseFrameTruth(const char *metadata);

// The head as the rig and calibration describe it.
struct RigFacts {
    std::optional<double> baseline_mm, focal_length_mm, pixel_pitch_um, focal_length_px;
    std::optional<int> image_width, image_height;
    int min_disparity = 0, num_disparities = 0;   // the matcher's search (0: unknown)
    bool ground_transform = false;                // a `ground` transform is listed
    double applied_inclination_deg = 0;           // its inclination_deg (Eq. 1), default 0
    double applied_camera_height_mm = 1500;       // its camera_height_mm, default 1500
};

// rig_yaml: source block (baseline_mm, focal_length_mm, pixel_pitch_um, image_width,
// image_height), matcher block (min_disparity, num_disparities), transforms (ground).
// calibration_yaml: OpenCV FileStorage (baseline_mm, focal_length_px, image_width/height).
RigFacts parseRigFacts(const char *rig_yaml, const char *calibration_yaml);

} // namespace binocle::paper
