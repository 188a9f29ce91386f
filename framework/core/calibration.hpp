// SPDX-License-Identifier: MIT
// Stereo calibration: the file format `binocle calibrate` writes, sources publish and
// every pipeline rectifies with.
//
// Format: OpenCV FileStorage YAML (%YAML:1.0) with the keys of OpenCV's stereo_calib
// sample, lengths in millimetres:
//   image_width, image_height   int     size the calibration was made at
//   M1, D1, M2, D2              matrix  intrinsics and distortion of left / right
//   R, T                        matrix  right camera w.r.t. left (x_r = R x_l + T), T in mm
//   rectified                   int     1: images are already rectified (R1 = R2 = I)
//   R1, R2, P1, P2, Q           matrix  rectification (written; recomputed on load)
//   baseline_mm, focal_length_px, rms_px, configuration   informative
//   source                      text    where a published calibration came from (a bag and
//                                       its topics): named in every refusal of it
// Written with FileStorage; read with the strict YAML loader (FileStorage's parser does
// not return on some mangled files): any other key, a second document, a duplicate key
// or a number that is not plain decimal is refused with its line and column.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace binocle {

struct StereoCalibration {
    cv::Size image_size;
    cv::Mat M1, D1, M2, D2; // CV_64F 3x3, 1xN
    cv::Mat R, T;           // CV_64F 3x3, 3x1 (mm)
    bool rectified = false;
    cv::Mat R1, R2, P1, P2, Q; // from computeRectification()
    double rms_px = -1;        // reprojection error, < 0 when unknown
    std::string configuration; // e.g. "B150_f8"

    // Baseline |T| in mm, and focal length of the rectified pair in px (P1(0,0)).
    double baselineMm() const;
    double focalLengthPx() const;

    // Fills R1, R2, P1, P2, Q (cv::stereoRectify, CALIB_ZERO_DISPARITY, alpha 0).
    void computeRectification();

    // Throws binocle::Error naming `origin` and the key unless M1, M2 are camera matrices
    // with positive focal lengths, every value is finite, R is a rotation and the
    // baseline is > 0 and <= kMaxBaselineMm. fromYaml() calls it.
    void validate(const std::string &origin) const;
    static constexpr double kMaxBaselineMm = 1e6; // 1 km: a larger one is a unit mistake

    // Parse FileStorage YAML text. `origin` names the file in errors. Throws binocle::Error
    // naming the origin, the key that is missing or malformed and, where it has one, its
    // line and column.
    static StereoCalibration fromYaml(const std::string &text, const std::string &origin);
    static StereoCalibration load(const std::string &path);
    std::string toYaml() const;
    // Writes atomically (temporary file + rename).
    void save(const std::string &path) const;

    // An ideal rectified pair: focal length f_px, principal point at the centre.
    static StereoCalibration ideal(cv::Size size, double focal_length_px, double baseline_mm,
                                   double cx = -1, double cy = -1);
};

// An image size as messages write it: "640x480" (width x height).
std::string sizeText(cv::Size size);

} // namespace binocle
