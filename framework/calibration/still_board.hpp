// SPDX-License-Identifier: MIT
// Live capture of calibration pairs: take a pair when the board, seen in both images,
// has been still for a few frames, and only once per position.
#pragma once

#include "calibration/board.hpp"

namespace binocle {

class StillBoard {
public:
    // `frames` consecutive frames in which no corner moved more than `still_px`; the next
    // pair only after the board moved on average more than `move_px` from the last one.
    StillBoard(int frames, double still_px, double move_px);

    // One frame's views of the board; true when this frame is the one to take.
    bool update(const BoardView &left, const BoardView &right);
    int stillFrames() const { return still_; }

private:
    int frames_;
    double stillPx_, movePx_;
    int still_ = 0;
    std::vector<cv::Point2f> prevLeft_, prevRight_, takenLeft_;
};

} // namespace binocle
