// SPDX-License-Identifier: MIT
// sgbm: Matcher plugin wrapping OpenCV's semi-global block matcher, cv::StereoSGBM.
#include "common/opencv_matcher.hpp"

#include <binocle/plugin.hpp>

#include <cstdint>
#include <opencv2/calib3d.hpp>
#include <string>
#include <vector>

namespace {

using binocle::sdk::Param;

class SemiGlobalMatcher : public binocle::plugins::OpenCvMatcher<cv::StereoSGBM> {
public:
    // The keys shared with bm come first (common/opencv_matcher.hpp), then
    // cv::StereoSGBM's own. block_size stops at 21: beyond, the derived penalties
    // overflow OpenCV's 16-bit path costs (README.md has the figures).
    static std::vector<binocle_param_desc> parameters() {
        return binocle::plugins::withSharedMatcherParameters({
            Param::integer("block_size", "5").min(1).max(21).odd().unit("px")
                .help("side of the square window whose costs are summed; OpenCV advises 3..11"),
            Param::integer("p1", "0").min(0).max(32767)
                .help("penalty for a disparity change of 1 px between neighbours; unset or 0 = 8 * block_size^2"),
            Param::integer("p2", "0").min(0).max(32767)
                .help("penalty for a disparity change of more than 1 px, > p1; unset or 0 = 32 * block_size^2"),
            Param::choice("mode", "sgbm", "sgbm|hh|sgbm_3way|hh4")
                .help("5 paths (sgbm), 8 paths (hh, much more memory), 3-way (sgbm_3way, faster) or 4 paths (hh4)"),
        });
    }

    SemiGlobalMatcher(const binocle::sdk::Params &p, binocle::sdk::Host &host)
        : OpenCvMatcher("sgbm", p, parameters(), 1) {
        const int block = static_cast<int>(p.integer("block_size"));
        const Penalty p1 = penalty(p, "p1", 8, block);
        const Penalty p2 = penalty(p, "p2", 32, block);
        if (p2.value <= p1.value)
            throw binocle::sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT,
                                      "sgbm: p2 = " + p2.text() + ": expected more than p1 = " + p1.text() +
                                          " (cv::StereoSGBM needs p2 > p1)");
        stereo_->setBlockSize(block);
        stereo_->setP1(p1.value);
        stereo_->setP2(p2.value);
        stereo_->setMode(modeOf(p.string("mode")));
        host.debug("block_size " + std::to_string(block) + ", p1 " + p1.text() + ", p2 " + p2.text() + ", mode " + p.string("mode"));
    }

private:
    struct Penalty {
        int value;
        std::string origin; // "set", or the rule it was derived by
        std::string text() const { return std::to_string(value) + " (" + origin + ")"; }
    };

    // The value set in the rig, else OpenCV's rule of thumb factor * channels *
    // block_size^2, with one channel since the pair is matched in grey.
    static Penalty penalty(const binocle::sdk::Params &p, const char *key, int factor, int block) {
        const int64_t v = p.integer(key);
        if (p.isExplicit(key) && v > 0) return {static_cast<int>(v), "set"};
        return {factor * block * block, "derived: " + std::to_string(factor) + " * block_size^2"};
    }

    static int modeOf(const std::string &mode) {
        if (mode == "hh") return cv::StereoSGBM::MODE_HH;
        if (mode == "sgbm_3way") return cv::StereoSGBM::MODE_SGBM_3WAY;
        if (mode == "hh4") return cv::StereoSGBM::MODE_HH4;
        return cv::StereoSGBM::MODE_SGBM;
    }
};

} // namespace

BINOCLE_EXPORT_MATCHER(SemiGlobalMatcher, "sgbm", "1.0.0", "OpenCV semi-global block matching (cv::StereoSGBM)")
