// SPDX-License-Identifier: MIT
// What the paper evaluator learns from its input besides the cloud: the truth the
// source attaches to a frame (metadata YAML), the head's calibration (calibration YAML)
// and what the host learnt through the other plugins' tables (the matcher's search, the
// ground frame's pose). No other plugin's settings are read: the evaluator works with
// any matcher and any transform that makes the ground frame.
#pragma once

#include "method/design.hpp"
#include "method/ground_plane.hpp"

#include <binocle/abi.h>

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

// The head as the calibration and the host describe it.
struct RigFacts {
    // From the calibration (OpenCV FileStorage: baseline_mm, focal_length_px, image_width/height).
    std::optional<double> baseline_mm, focal_length_px;
    std::optional<int> image_width, image_height;
    // From the host: the matcher's disparity_range (0: unknown) and the pose of Eq. 1 the
    // transform that made the ground frame applied (its defaults when none says).
    int min_disparity = 0, num_disparities = 0;
    bool ground_pose_known = false;
    double applied_inclination_deg = 0;
    double applied_camera_height_mm = method::kDefaultCameraHeightMm;
};

// The calibration's part of RigFacts (null or empty: nothing known).
RigFacts parseCalibrationFacts(const char *calibration_yaml);
// Adds what the host passed in `in` (only the members its struct_size reaches).
void addHostFacts(RigFacts &facts, const binocle_eval_input &in);

} // namespace binocle::paper
