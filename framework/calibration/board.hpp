// SPDX-License-Identifier: MIT
// The calibration chessboard: its description (--board 9x6 --square-mm 25), finding it
// in an image with sub-pixel corners, and the figures that say whether a view is usable.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace binocle {

struct BoardSpec {
    int cols = 0, rows = 0; // inner corners per row / per column
    double square_mm = 0;   // side of one square

    cv::Size patternSize() const { return {cols, rows}; }
    // The corners in the board's own frame (z = 0), in the order the detector returns them.
    std::vector<cv::Point3f> objectPoints() const;

    // "9x6" (or "9X6") and a square size; throws binocle::Error naming the option and the value.
    static BoardSpec parse(const std::string &board, double square_mm);
};

// One image's view of the board.
struct BoardView {
    bool found = false;
    std::vector<cv::Point2f> corners; // sub-pixel, row by row, cols per row
    double area_percent = 0;          // the corners' outline as a share of the image
    double edge_width_px = -1;        // median 10-90 % rise across the squares' edges; < 0: unknown
    std::string detector;             // "classic" or "sb"
};

// Finds the board: cv::findChessboardCorners (adaptive threshold, normalised image) and
// cv::cornerSubPix with a window scaled to the square size, falling back to
// cv::findChessboardCornersSB. `fast` adds CALIB_CB_FAST_CHECK and skips the fallback
// (live video, where most frames have no board). Grey or BGR 8-bit input.
BoardView findBoard(const cv::Mat &image, const BoardSpec &board, bool fast = false);

// Mean and largest distance between the corners of two views of the same board.
double meanCornerShiftPx(const std::vector<cv::Point2f> &a, const std::vector<cv::Point2f> &b);
double maxCornerShiftPx(const std::vector<cv::Point2f> &a, const std::vector<cv::Point2f> &b);

} // namespace binocle
