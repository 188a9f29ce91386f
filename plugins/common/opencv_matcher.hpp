// SPDX-License-Identifier: MIT
// The part of the OpenCV stereo matchers (bm, sgbm) that does not depend on the
// algorithm: the settings both accept, input checks, zero-copy views of binocle_image,
// grey conversion, and OpenCV's fixed-point disparity turned into Binocle's float one.
//
// Header-only; plugins/common has no CMakeLists.txt on purpose (every folder with one
// is built as a plugin).
#pragma once


#include <binocle/plugin.hpp>

#include <cstdint>
#include <new>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>
#include <vector>

namespace binocle::plugins {

// Settings that bm and sgbm both accept, with the same meaning, unit and default, so
// that a rig changes matcher by changing `plugin:` alone. speckle_range is in pixels
// for both (cv::StereoBM wants 1/16 px, cv::StereoSGBM px: OpenCvMatcher scales).
// min_disparity is >= 0 because Binocle reads any disparity <= 0 as invalid.
inline std::vector<binocle_param_desc> sharedMatcherParameters() {
    using sdk::Param;
    return {
        Param::integer("min_disparity", "0").min(0).unit("px")
            .help("smallest disparity searched"),
        Param::integer("num_disparities", "64").min(16).multipleOf(16).unit("px")
            .help("width of the search window: disparities min_disparity .. min_disparity + num_disparities - 1"),
        Param::integer("pre_filter_cap", "31").min(1).max(63)
            .help("the prefiltered image is clipped to [-pre_filter_cap, pre_filter_cap]"),
        Param::integer("uniqueness_ratio", "10").min(0).max(100).unit("%")
            .help("the best cost must beat the second best (away from +-1 px) by this margin; 0 = no check"),
        Param::integer("speckle_window_size", "100").min(0).unit("px")
            .help("connected regions of similar disparity smaller than this many pixels are invalidated; 0 = off"),
        Param::integer("speckle_range", "2").min(1).unit("px")
            .help("largest disparity step between neighbours of one region for the speckle filter (off: speckle_window_size 0)"),
        Param::integer("disp12_max_diff", "1").min(-1).unit("px")
            .help("largest difference allowed in the left-right consistency check; -1 = no check (bm only: sgbm always checks, with at least 1)"),
    };
}

// Appends `own` to `shared`: a plugin's full settings table.
inline std::vector<binocle_param_desc> withSharedMatcherParameters(std::vector<binocle_param_desc> own) {
    std::vector<binocle_param_desc> all = sharedMatcherParameters();
    all.insert(all.end(), own.begin(), own.end());
    return all;
}

using sdk::checkMatcherImages;
using sdk::pixelFormatName;
using sdk::sizeText;

// A cv::Mat header on the image's pixels (no copy), honouring its stride.
inline cv::Mat wrapImage(const binocle_image &im) {
    int type = 0;
    switch (im.format) {
    case BINOCLE_PIXEL_GRAY8: type = CV_8UC1; break;
    case BINOCLE_PIXEL_GRAY16: type = CV_16UC1; break;
    case BINOCLE_PIXEL_BGR8:
    case BINOCLE_PIXEL_RGB8: type = CV_8UC3; break;
    case BINOCLE_PIXEL_FLOAT32: type = CV_32FC1; break;
    default:
        throw sdk::Error(BINOCLE_ERR_UNSUPPORTED, "cannot view an image of " + pixelFormatName(im.format));
    }
    return cv::Mat(im.height, im.width, type, im.data, static_cast<size_t>(im.stride_bytes));
}


// The image as 8-bit grey: a view of its pixels when already GRAY8, else converted
// into `buffer` (reused from call to call).
inline cv::Mat greyView(const binocle_image &im, cv::Mat &buffer) {
    const cv::Mat m = wrapImage(im);
    if (im.format == BINOCLE_PIXEL_GRAY8) return m;
    cv::cvtColor(m, buffer, im.format == BINOCLE_PIXEL_RGB8 ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
    return buffer;
}

// OpenCV's CV_16S disparity (4 fractional bits; (min_disparity - 1) * 16 where it found
// no match) -> pixels, BINOCLE_INVALID_DISPARITY where it found none.
inline void writeDisparity(const cv::Mat &fixed, int minDisparity, cv::Mat &out) {
    CV_Assert(fixed.type() == CV_16SC1 && out.type() == CV_32FC1 && fixed.size() == out.size());
    const int smallestValid = minDisparity * cv::StereoMatcher::DISP_SCALE;
    const float scale = 1.0f / cv::StereoMatcher::DISP_SCALE;
    for (int v = 0; v < fixed.rows; ++v) {
        const int16_t *src = fixed.ptr<int16_t>(v);
        float *dst = out.ptr<float>(v);
        for (int u = 0; u < fixed.cols; ++u)
            dst[u] = src[u] < smallestValid ? BINOCLE_INVALID_DISPARITY : static_cast<float>(src[u]) * scale;
    }
}

// A Binocle matcher around an OpenCV one (cv::StereoBM or cv::StereoSGBM): the derived
// class sets the algorithm's own settings on stereo_; this class sets the shared ones,
// does the checks and conversions, and calls OpenCV.
template <class OpenCvStereo>
class OpenCvMatcher : public sdk::Matcher {
public:
    void compute(const binocle_image &left, const binocle_image &right, binocle_image &disparity) override {
        checkMatcherImages(left, right, disparity);
        const int minDisparity = stereo_->getMinDisparity();
        const int numDisparities = stereo_->getNumDisparities();
        if (minDisparity + numDisparities >= left.width)
            throw sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT,
                             name_ + ": min_disparity + num_disparities = " + std::to_string(minDisparity + numDisparities) +
                                 ": expected less than the image width " + std::to_string(left.width));
        checkImageSize(left.width, left.height);
        try {
            stereo_->compute(greyView(left, greyLeft_), greyView(right, greyRight_), fixed_);
        } catch (const cv::Exception &e) {
            throw sdk::Error(BINOCLE_ERR_INTERNAL, name_ + ": OpenCV failed on a " + sizeText(left) + " pair: " + e.err);
        } catch (const std::bad_alloc &) {
            throw sdk::Error(BINOCLE_ERR_INTERNAL, name_ + ": out of memory matching a " + sizeText(left) + " pair with num_disparities " +
                                                       std::to_string(numDisparities));
        }
        cv::Mat out = wrapImage(disparity);
        writeDisparity(fixed_, minDisparity, out);
    }

    std::pair<int32_t, int32_t> disparityRange() const override {
        return {stereo_->getMinDisparity(), stereo_->getNumDisparities()};
    }

protected:
    // Applies the shared settings, checked by the SDK against the plugin's table.
    // speckleUnitsPerPixel: how many units of OpenCV's speckle range make one pixel.
    OpenCvMatcher(std::string name, const sdk::CheckedParams &p, int speckleUnitsPerPixel)
        : name_(std::move(name)), stereo_(OpenCvStereo::create()) {
        stereo_->setMinDisparity(static_cast<int>(p.integer("min_disparity")));
        stereo_->setNumDisparities(static_cast<int>(p.integer("num_disparities")));
        stereo_->setPreFilterCap(static_cast<int>(p.integer("pre_filter_cap")));
        stereo_->setUniquenessRatio(static_cast<int>(p.integer("uniqueness_ratio")));
        stereo_->setSpeckleWindowSize(static_cast<int>(p.integer("speckle_window_size")));
        stereo_->setSpeckleRange(static_cast<int>(p.integer("speckle_range")) * speckleUnitsPerPixel);
        stereo_->setDisp12MaxDiff(static_cast<int>(p.integer("disp12_max_diff")));
    }
    // Throws when the settings cannot work on images of this size.
    virtual void checkImageSize(int /*width*/, int /*height*/) const {}

    const std::string name_;
    cv::Ptr<OpenCvStereo> stereo_;

private:
    cv::Mat greyLeft_, greyRight_, fixed_;
};

} // namespace binocle::plugins
