// SPDX-License-Identifier: MIT
// Disparity image formats: KITTI 16-bit PNG, PFM, colourised PNG.
#include "core/image_io.hpp"

#include "files/atomic_file.hpp"
#include "core/error.hpp"
#include "input/image_file.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace binocle {

void writeImage(const std::string &path, const cv::Mat &image) {
    // Encoded in memory, then written through writeFileAtomic's own descriptor: the file is
    // never opened again by name (a symlink swapped in meanwhile is not followed).
    const size_t dot = path.rfind('.');
    const size_t slash = path.rfind('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
        throw Error("cannot write image " + path + ": no extension to choose the format by");
    std::vector<uchar> bytes;
    bool ok = false;
    try {
        ok = cv::imencode(path.substr(dot), image, bytes);
    } catch (const cv::Exception &e) {
        throw Error("cannot write image " + path + ": " + e.err);
    }
    if (!ok) throw Error("cannot write image " + path);
    writeFileAtomic(path, std::string(bytes.begin(), bytes.end()));
}

void writeDisparityPng16(const std::string &path, const cv::Mat &disparity) {
    CV_Assert(disparity.type() == CV_32F);
    cv::Mat out(disparity.size(), CV_16U);
    for (int v = 0; v < disparity.rows; ++v) {
        const float *d = disparity.ptr<float>(v);
        uint16_t *o = out.ptr<uint16_t>(v);
        for (int u = 0; u < disparity.cols; ++u) {
            const float x = d[u];
            o[u] = (std::isfinite(x) && x > 0) ? static_cast<uint16_t>(std::min(65535.0f, std::round(x * 256.0f))) : 0;
        }
    }
    writeImage(path, out);
}

cv::Mat readDisparityPng16(const std::string &path) {
    cv::Mat raw;
    try {
        raw = input::readImage(path, cv::IMREAD_UNCHANGED, "disparity PNG");
    } catch (const input::ImageFileError &e) {
        throw Error(e.what());
    }
    if (raw.type() != CV_16U) throw Error(path + ": expected a 16-bit single-channel PNG (KITTI disparity)");
    cv::Mat d;
    raw.convertTo(d, CV_32F, 1.0 / 256.0);
    d.setTo(-1.0f, raw == 0);
    return d;
}

void writePfm(const std::string &path, const cv::Mat &image) {
    CV_Assert(image.depth() == CV_32F && (image.channels() == 1 || image.channels() == 3));
    cv::Mat out = image;
    if (image.channels() == 1) {
        // A disparity map: invalid (<= 0) pixels become inf, as Middlebury's PFM files mark them.
        out = image.clone();
        out.setTo(std::numeric_limits<float>::infinity(), ~(image > 0) & (image == image));
    }
    writeFileAtomic(path, input::encodePfm(out)); // the one PFM writer: scale -1, little-endian
}

cv::Mat readPfm(const std::string &path) {
    try {
        return input::readPfm(path);
    } catch (const input::ImageFileError &e) {
        throw Error(e.what());
    }
}

cv::Mat colorizeDisparity(const cv::Mat &disparity, double max_disparity) {
    CV_Assert(disparity.type() == CV_32F);
    cv::Mat valid = disparity > 0;
    if (max_disparity <= 0) {
        double mn = 0, mx = 0;
        cv::minMaxLoc(disparity, &mn, &mx, nullptr, nullptr, valid);
        max_disparity = mx > 0 ? mx : 1;
    }
    cv::Mat scaled;
    disparity.convertTo(scaled, CV_8U, 255.0 / max_disparity);
    cv::Mat color;
    cv::applyColorMap(scaled, color, cv::COLORMAP_TURBO);
    color.setTo(cv::Scalar::all(0), ~valid);
    return color;
}

} // namespace binocle
