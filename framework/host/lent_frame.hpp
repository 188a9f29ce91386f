// SPDX-License-Identifier: MIT
// A frame a source lends (Source::grab): zero-copy views of its planes, given back to the
// plugin when the object dies.
#pragma once

#include <binocle/abi.h>

#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace binocle {

// A frame lent by a source; released when this object dies. Views are zero-copy.
class LentFrame {
public:
    LentFrame(std::shared_ptr<void> keep, const binocle_source_api *api, binocle_source *src,
              const binocle_stereo_frame &f);
    // A frame whose pixels `keep` holds (the copy of an isolated source's frame): nothing
    // to give back but `keep`.
    LentFrame(std::shared_ptr<void> keep, const binocle_stereo_frame &f);
    ~LentFrame();
    LentFrame(const LentFrame &) = delete;
    LentFrame &operator=(const LentFrame &) = delete;
    const binocle_stereo_frame &raw() const { return frame_; }
    cv::Mat left() const;  // view, no copy
    cv::Mat right() const; // view, no copy
    // Extra plane by name ("gt_disparity"), or an empty Mat.
    cv::Mat extra(const std::string &name) const;
    std::string metadata() const { return frame_.metadata ? frame_.metadata : ""; }

private:
    std::shared_ptr<void> keep_;
    const binocle_source_api *api_;
    binocle_source *src_;
    binocle_stereo_frame frame_;
};

} // namespace binocle
