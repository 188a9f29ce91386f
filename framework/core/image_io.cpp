// SPDX-License-Identifier: MIT
// Disparity image formats: KITTI 16-bit PNG, PFM, colourised PNG.
#include "core/image_io.hpp"

#include "core/atomic_file.hpp"
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
    writeFileAtomicWith(path, [&](const std::string &tmp) {
        bool ok = false;
        try {
            ok = cv::imwrite(tmp, image);
        } catch (const cv::Exception &e) {
            throw Error("cannot write image " + path + ": " + e.err);
        }
        if (!ok) throw Error("cannot write image " + path);
    });
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
    std::ostringstream os;
    os << (image.channels() == 3 ? "PF" : "Pf") << "\n" << image.cols << " " << image.rows << "\n-1.0\n";
    std::string bytes = os.str();
    const size_t rowBytes = static_cast<size_t>(image.cols) * image.channels() * sizeof(float);
    for (int v = image.rows - 1; v >= 0; --v) {
        std::string row(reinterpret_cast<const char *>(image.ptr(v)), rowBytes);
        if (image.channels() == 1) {
            float *f = reinterpret_cast<float *>(row.data());
            for (int u = 0; u < image.cols; ++u)
                if (!(f[u] > 0) && std::isfinite(f[u])) f[u] = std::numeric_limits<float>::infinity();
        }
        bytes += row;
    }
    writeFileAtomic(path, bytes);
}

cv::Mat readPfm(const std::string &path) {
    // The header is checked against the image limits and the file's size before
    // anything is allocated: a 20-byte file claiming 65536 x 65536 is refused at once.
    std::vector<uint8_t> bytes;
    input::ImageInfo info;
    std::string problem;
    try {
        bytes = input::readImageFileBytes(path, "PFM file");
    } catch (const input::ImageFileError &e) {
        throw Error(e.what());
    }
    if (!input::inspectImage(bytes.data(), bytes.size(), info, problem)) throw Error("PFM file '" + path + "': " + problem);
    if (info.format != "pfm") throw Error(path + ": not a PFM file (expected 'Pf' or 'PF', width, height, scale)");
    const int w = static_cast<int>(info.width), h = static_cast<int>(info.height), ch = info.channels;
    cv::Mat m(h, w, CV_32FC(ch));
    const bool bigEndian = info.scale > 0;
    const size_t rowBytes = static_cast<size_t>(w) * ch * sizeof(float);
    for (int v = h - 1, r = 0; v >= 0; --v, ++r) {
        std::memcpy(m.ptr(v), bytes.data() + info.dataOffset + rowBytes * static_cast<size_t>(r), rowBytes);
        if (bigEndian) {
            auto *b = m.ptr(v);
            for (int i = 0; i < w * ch; ++i) std::swap(b[4 * i], b[4 * i + 3]), std::swap(b[4 * i + 1], b[4 * i + 2]);
        }
    }
    return m;
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
