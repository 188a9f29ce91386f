// SPDX-License-Identifier: MIT
// Stereo calibration from chessboard pairs: screens each pair (board found in both
// images, large enough, sharp, same corner order), calibrates each camera, then the
// pair, drops pairs whose reprojection error stands out and calibrates again.
#pragma once

#include "calibration/board.hpp"
#include "core/calibration.hpp"
#include "core/json.hpp"

#include <string>
#include <vector>

namespace binocle {

struct CalibrationOptions {
    BoardSpec board;
    double min_board_area_percent = 1.5; // smaller boards constrain the distortion poorly
    double max_edge_width_px = 4.0;      // blurred beyond this (BoardView::edge_width_px)
    double max_pair_error_px = 1.0;      // after a first calibration, pairs above are dropped
    int min_pairs = 4;                   // fewer good pairs: no calibration
    bool fix_intrinsic = false;          // stereoCalibrate with CALIB_FIX_INTRINSIC instead of refining
    bool fix_k3 = false;                 // CALIB_FIX_K3: k1, k2, p1, p2 only
};

// What happened to one pair.
struct PairRecord {
    std::string id;          // "01" for left01.jpg / right01.jpg, or the frame number
    std::string left_name, right_name;
    bool used = false;       // part of the final calibration
    std::string rejection;   // why not, when !used
    BoardView left, right;
    double error_left_px = -1, error_right_px = -1; // RMS reprojection error, used pairs
    double errorPx() const;  // both cameras together; < 0 when not calibrated
};

struct CalibrationResult {
    StereoCalibration calibration;
    std::vector<PairRecord> pairs; // every pair offered, in order
    double rms_px = 0;             // stereo RMS reprojection error over the used pairs
    double rms_left_px = 0, rms_right_px = 0; // of the single-camera calibrations
    int rounds = 0;                // calibrations run (1 + recalibrations after dropping pairs)
    int usedPairs() const;
};

class StereoCalibrator {
public:
    explicit StereoCalibrator(CalibrationOptions options);

    // Finds the board in both images and screens the pair; keeps it when usable.
    const PairRecord &addPair(const std::string &id, const cv::Mat &left, const cv::Mat &right,
                              const std::string &leftName = "", const std::string &rightName = "");
    // Same with the board already found (live capture finds it to see when it is still).
    const PairRecord &addViews(const std::string &id, cv::Size imageSize, BoardView left, BoardView right,
                               const std::string &leftName = "", const std::string &rightName = "");
    // A pair that could not even be read (missing file, unreadable image).
    const PairRecord &addRejected(const std::string &id, const std::string &reason, const std::string &leftName = "",
                                  const std::string &rightName = "");

    int goodPairs() const;
    const std::vector<PairRecord> &pairs() const { return pairs_; }
    const CalibrationOptions &options() const { return options_; }
    cv::Size imageSize() const { return imageSize_; }

    // Calibrates; throws binocle::Error when fewer than min_pairs pairs are usable.
    CalibrationResult calibrate() const;

private:
    CalibrationOptions options_;
    std::vector<PairRecord> pairs_;
    cv::Size imageSize_;
};

// The JSON report written beside the calibration file: per-pair errors, overall RMS,
// baseline, focal lengths, rejected pairs with their reasons. `pixelPitchUm` <= 0: unknown.
Json calibrationReport(const CalibrationResult &result, const CalibrationOptions &options, double pixelPitchUm);

} // namespace binocle
