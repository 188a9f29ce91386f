// SPDX-License-Identifier: MIT
// bm: Matcher plugin wrapping OpenCV's block matcher, cv::StereoBM.
#include "common/opencv_matcher.hpp"

#include <binocle/plugin.hpp>

#include <algorithm>
#include <opencv2/calib3d.hpp>
#include <string>
#include <vector>

namespace {

using binocle::sdk::Param;

class BlockMatcher : public binocle::plugins::OpenCvMatcher<cv::StereoBM> {
public:
    // The keys shared with sgbm come first (common/opencv_matcher.hpp), then
    // cv::StereoBM's own, with the ranges cv::StereoBM enforces.
    static std::vector<binocle_param_desc> parameters() {
        return binocle::plugins::withSharedMatcherParameters({
            Param::integer("block_size", "15").min(5).max(255).odd().unit("px")
                .help("side of the square window whose sum of absolute differences is compared"),
            Param::choice("pre_filter_type", "xsobel", "normalized_response|xsobel")
                .help("image prefilter: horizontal Sobel, or normalized response"),
            Param::integer("pre_filter_size", "9").min(5).max(255).odd().unit("px")
                .help("window of the normalized_response prefilter"),
            Param::integer("texture_threshold", "10").min(0)
                .help("windows whose summed prefiltered texture is below this are invalid; 0 = off"),
        });
    }

    // cv::StereoBM's speckle range is in 1/16 px: it filters the fixed-point map.
    BlockMatcher(const binocle::sdk::CheckedParams &p, binocle::sdk::Host &)
        : OpenCvMatcher("bm", p, cv::StereoMatcher::DISP_SCALE) {
        stereo_->setBlockSize(static_cast<int>(p.integer("block_size")));
        stereo_->setPreFilterType(p.string("pre_filter_type") == "xsobel" ? cv::StereoBM::PREFILTER_XSOBEL
                                                                           : cv::StereoBM::PREFILTER_NORMALIZED_RESPONSE);
        stereo_->setPreFilterSize(static_cast<int>(p.integer("pre_filter_size")));
        stereo_->setTextureThreshold(static_cast<int>(p.integer("texture_threshold")));
    }

private:
    // cv::StereoBM refuses a window as large as the image's smaller side.
    void checkImageSize(int width, int height) const override {
        const int block = stereo_->getBlockSize();
        if (block >= std::min(width, height))
            throw binocle::sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT,
                                      "bm: block_size = " + std::to_string(block) + ": expected less than " +
                                          std::to_string(std::min(width, height)) + ", the smaller side of the image");
    }
};

} // namespace

BINOCLE_EXPORT_MATCHER(BlockMatcher, "bm", "1.0.0", "OpenCV block matching (cv::StereoBM)")
