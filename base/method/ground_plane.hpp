// SPDX-License-Identifier: MIT
// Indicators of Experiment 2 (METHOD.md): the ground plane fitted to the cloud (ground
// offset, recovered inclination, angular error) and the centre-of-coordinates offset of
// a known object.
#pragma once

#include "method/cloud_view.hpp"
#include "method/density_grid.hpp"
#include "method/panel.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace binocle::method {

struct GroundPlaneOptions {
    double inlier_mm = 50;         // distance to the plane that makes a point an inlier
    double max_tilt_deg = 30;      // planes steeper than this (against horizontal) are not ground
    int iterations = 400;          // RANSAC draws
    uint32_t seed = 1;             // of the draws: the same cloud gives the same plane
    size_t max_points = 40000;     // RANSAC scores a random subset of this size
    Extent x, y;                   // where to look; not valid() (the default): everywhere
    double max_height_mm = 1e9;    // only points lower than this (Z) are candidates
};

// Z = slope_x * X + slope_y * Y + offset, in the ground frame (mm).
struct GroundPlane {
    bool found = false;
    double normal[3] = {0, 0, 1}; // unit normal, Z component > 0
    double offset_mm = 0;         // height of the plane under the camera origin (X = Y = 0): ground offset, 0 ideally
    double pitch_deg = 0;         // atan(dZ/dY): > 0 when the ground rises with range
    double roll_deg = 0;          // atan(dZ/dX): > 0 when the ground rises to the right
    int64_t inliers = 0;          // of all candidate points, after the least-squares refinement
    int64_t candidates = 0;
    double rms_mm = 0;            // of the inliers' distances to the plane

    double heightAt(double x_mm, double y_mm) const;
};

// RANSAC over planes whose normal is within max_tilt_deg of vertical, then a total least
// squares refinement (plane through the inliers' mean, normal = smallest principal axis),
// repeated twice with the inliers of the refined plane.
GroundPlane fitGroundPlane(const CloudView &cloud, const GroundPlaneOptions &options = {});

// The camera's inclination recovered from the fitted ground: the ground transform
// applied `applied_inclination_deg` (Eq. 1); a camera pitched delta further down than
// that sees the ground rise with range by atan(dZ/dY) = delta, so theta = applied + pitch.
double recoveredInclinationDeg(double applied_inclination_deg, const GroundPlane &plane);

// A scene object whose true position is known (frame metadata, or tape-measured).
struct KnownObject {
    std::string name;
    double center_mm[3] = {0, 0, 0}; // ground frame
    double size_mm[3] = {0, 0, 0};   // width X, depth Y, height Z
    double nearFaceRangeMm() const { return center_mm[1] - size_mm[1] / 2; }
};

// Centre-of-coordinates offset: where the cloud puts a known object against where it is.
// Lateral: middle of the localised object's lateral extent minus the true centre X.
// Range: the localised object's range (median Y of its points: the face the camera sees)
// minus the true range of its near face.
struct ObjectOffset {
    bool found = false;
    int object_id = 0;             // LocalisedObject::id of the match
    double lateral_mm = 0, range_mm = 0;
    double distance_mm = 0;        // hypot(lateral, range)
    double measured_x_mm = 0, measured_range_mm = 0;
    double true_x_mm = 0, true_range_mm = 0;
    PanelReading reading;          // locateKnownObject: its reading (edges, cells), for drawing
};

// Reads a known object where it should be, as the E1 panel is read (readPanel): the
// points above the ground within its true lateral span +- lateral_margin_mm and below its
// true top + lateral_margin_mm, the densest
// range band near its near face (options' range search and margin), the lateral edges
// of the band's occupied front-view cells and the median range. Robust where the top
// view's regions merge (a smeared cloud joining the object to its neighbours).
// options.expected_range_mm and options.lateral are set from `truth`.
ObjectOffset locateKnownObject(const CloudView &cloud, const KnownObject &truth, PanelReadingOptions options,
                               double lateral_margin_mm);

// Matches `truth` to the nearest localised object (by lateral centre and range) within
// max_distance_mm; found = false when none is that close.
ObjectOffset objectOffset(const std::vector<LocalisedObject> &objects, const KnownObject &truth,
                          double max_distance_mm);

} // namespace binocle::method
