// SPDX-License-Identifier: MIT
// Live capture of calibration pairs: stillness of the board over consecutive frames.
#include "calibration/still_board.hpp"

namespace binocle {

StillBoard::StillBoard(int frames, double still_px, double move_px) : frames_(frames), stillPx_(still_px), movePx_(move_px) {}

bool StillBoard::update(const BoardView &left, const BoardView &right) {
    if (!left.found || !right.found) {
        still_ = 0;
        prevLeft_.clear();
        prevRight_.clear();
        return false;
    }
    const bool still = !prevLeft_.empty() && maxCornerShiftPx(left.corners, prevLeft_) < stillPx_ &&
                       maxCornerShiftPx(right.corners, prevRight_) < stillPx_;
    still_ = still ? still_ + 1 : 1;
    prevLeft_ = left.corners;
    prevRight_ = right.corners;
    if (still_ < frames_) return false;
    if (!takenLeft_.empty() && meanCornerShiftPx(left.corners, takenLeft_) <= movePx_) return false;
    takenLeft_ = left.corners;
    return true;
}

} // namespace binocle
