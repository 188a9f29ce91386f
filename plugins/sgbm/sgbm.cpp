// SPDX-License-Identifier: MIT
// sgbm: Matcher plugin wrapping OpenCV's semi-global block matcher, cv::StereoSGBM.
#include "common/opencv_matcher.hpp"

#include <binocle/plugin.hpp>

#include <algorithm>
#include <cmath>
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
            Param::integer("max_memory_mb", "2048").min(16).max(1048576).unit("MiB").limit()
                .help("refuse a pair whose working buffers cv::StereoSGBM would need more than this (estimated before matching)"),
        });
    }

    SemiGlobalMatcher(const binocle::sdk::CheckedParams &p, binocle::sdk::Host &host)
        : OpenCvMatcher("sgbm", p, 1) {
        const int block = static_cast<int>(p.integer("block_size"));
        const Penalty p1 = penalty(p, "p1", 8, block);
        const Penalty p2 = penalty(p, "p2", 32, block);
        if (p2.value <= p1.value)
            p.refuse("p2", p2.text(), "more than p1 = " + p1.text() + " (cv::StereoSGBM needs p2 > p1)");
        stereo_->setBlockSize(block);
        stereo_->setP1(p1.value);
        stereo_->setP2(p2.value);
        stereo_->setMode(modeOf(p.string("mode")));
        host.debug("block_size " + std::to_string(block) + ", p1 " + p1.text() + ", p2 " + p2.text() + ", mode " + p.string("mode"));
        mode_ = p.string("mode");
        maxMemoryBytes_ = static_cast<double>(p.integer("max_memory_mb")) * 1024 * 1024;
    }

protected:
    // cv::StereoSGBM allocates its buffers in one piece when matching starts; when that
    // fails OpenCV 4.6 throws from a destructor (buffer_area.cpp) and the process aborts,
    // past any catch. So the size is estimated here, from the buffer layout of
    // stereosgbm.cpp, and a pair that would need more than max_memory_mb is refused.
    void checkImageSize(int width, int height) const override {
        const double need = workingBytes(width, height);
        if (need > maxMemoryBytes_)
            throw binocle::sdk::Error(
                BINOCLE_ERR_INVALID_ARGUMENT,
                "sgbm: mode " + mode_ + " on a " + std::to_string(width) + "x" + std::to_string(height) +
                    " pair with num_disparities " + std::to_string(stereo_->getNumDisparities()) + " needs about " +
                    mebibytes(need) + " MiB of working memory" +
                    (mode_ == "hh" || mode_ == "hh4" ? " (a cost volume of width x height x num_disparities x 4 bytes)"
                                                     : "") +
                    "; expected at most max_memory_mb = " + mebibytes(maxMemoryBytes_) +
                    ": use fewer disparities, smaller images" +
                    (mode_ == "hh" || mode_ == "hh4" ? ", mode sgbm" : "") + " or raise max_memory_mb");
    }

private:
    static std::string mebibytes(double bytes) { return std::to_string(static_cast<long long>(bytes / 1048576.0 + 0.5)); }

    // Bytes of cv::StereoSGBM's buffers for one pair (OpenCV 4.6): a row of costs is
    // width1 x D 16-bit values, width1 = width - (min_disparity + num_disparities).
    // hh and hh4 keep two cost volumes of the whole image (C and S); sgbm keeps a few rows
    // and the path costs of two rows; sgbm_3way keeps a few rows per stripe (thread).
    double workingBytes(int width, int height) const {
        const double D = std::ceil(stereo_->getNumDisparities() / 16.0) * 16;
        const double width1 = std::max(1, width - stereo_->getMinDisparity() - stereo_->getNumDisparities());
        const double rowBytes = width1 * D * 2;
        const double hsumRows = (stereo_->getBlockSize() / 2) * 2 + 2;
        const double pathRows = 2 * (width1 + 2) * 8 * (D + 16) * 2; // 8 paths, two rows
        if (mode_ == "hh" || mode_ == "hh4") return 2 * rowBytes * height + rowBytes * (hsumRows + 1) + pathRows;
        if (mode_ == "sgbm_3way") return std::max(1, cv::getNumThreads()) * (rowBytes * (hsumRows + 4));
        return rowBytes * (hsumRows + 3) + pathRows;
    }

    std::string mode_;
    double maxMemoryBytes_ = 0;

    struct Penalty {
        int value;
        std::string origin; // "set", or the rule it was derived by
        std::string text() const { return std::to_string(value) + " (" + origin + ")"; }
    };

    // The value set in the rig, else OpenCV's rule of thumb factor * channels *
    // block_size^2, with one channel since the pair is matched in grey.
    static Penalty penalty(const binocle::sdk::CheckedParams &p, const char *key, int factor, int block) {
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
