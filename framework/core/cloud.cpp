// SPDX-License-Identifier: MIT
// Point clouds: triangulation from disparity and binary PLY.
#include "core/cloud.hpp"

#include "core/calibration.hpp"
#include "core/error.hpp"
#include "files/atomic_file.hpp"
#include "input/integer_range.hpp"

#include <binocle/text.hpp>

#include <cstring>
#include <fstream>
#include <sstream>

namespace binocle {

binocle_cloud Cloud::view() {
    binocle_cloud c{};
    c.count = static_cast<int64_t>(size());
    c.xyz = xyz.data();
    c.rgb = rgb.empty() ? nullptr : rgb.data();
    c.pixel = pixel.empty() ? nullptr : pixel.data();
    c.image_width = image_width;
    c.image_height = image_height;
    c.frame = frame;
    return c;
}

void Cloud::adopt(const binocle_cloud &view) {
    const auto n = static_cast<size_t>(view.count);
    xyz.resize(3 * n);
    if (!rgb.empty()) rgb.resize(3 * n);
    if (!pixel.empty()) pixel.resize(n);
    frame = view.frame;
}

Cloud cloudFromDisparity(const cv::Mat &disparity, const StereoCalibration &cal, const cv::Mat &left,
                         double max_range_mm) {
    Cloud cloud;
    CloudProjector(cal, max_range_mm).project(disparity, left, cloud);
    return cloud;
}

CloudProjector::CloudProjector(const StereoCalibration &cal, double max_range_mm)
    : maxRange_(max_range_mm) {
    if (cal.Q.empty()) throw Error("cloud: the calibration has no Q matrix (rectification not computed)");
    cv::Mat q64, r64;
    cal.Q.convertTo(q64, CV_64F);
    const cv::Matx44d Q(q64.reshape(1, 1).ptr<double>());
    cv::Matx33d R1t = cv::Matx33d::eye();
    if (!cal.R1.empty()) {
        cal.R1.convertTo(r64, CV_64F);
        R1t = cv::Matx33d(r64.reshape(1, 1).ptr<double>()).t();
    }
    // h = Q (u, v, d, 1): column k of Q multiplies the k-th input; the rotated
    // numerators are R1^T times the first three rows.
    for (int k = 0; k < 4; ++k) {
        const cv::Vec3d q(Q(0, k), Q(1, k), Q(2, k));
        const cv::Vec3d rotated = R1t * q;
        const double five[5] = {rotated[0], rotated[1], rotated[2], Q(2, k), Q(3, k)};
        for (int i = 0; i < 5; ++i) {
            double &slot = k == 0 ? col_[i] : k == 1 ? rowV_[i] : k == 2 ? disp_[i] : row1_[i];
            slot = five[i];
        }
    }
}

size_t CloudProjector::project(const cv::Mat &disparity, const cv::Mat &left, Cloud &cloud) const {
    CV_Assert(disparity.type() == CV_32F);
    const int rows = disparity.rows, cols = disparity.cols;
    const bool color = !left.empty() && left.size() == disparity.size();
    const bool bgr = color && left.channels() == 3;
    cloud.image_width = cols;
    cloud.image_height = rows;
    cloud.frame = BINOCLE_FRAME_CAMERA;
    // Size the arrays to the valid pixels: a cheap pass that the compiler vectorises,
    // so that growing the arrays never fills more than the new points.
    size_t valid = 0;
    for (int v = 0; v < rows; ++v) {
        const float *d = disparity.ptr<float>(v);
        int n = 0;
        for (int u = 0; u < cols; ++u) n += d[u] > 0.f;
        valid += static_cast<size_t>(n);
    }
    cloud.xyz.resize(3 * valid);
    cloud.pixel.resize(valid);
    if (color) cloud.rgb.resize(3 * valid);
    else cloud.rgb.clear();
    float *xyz = cloud.xyz.data();
    int32_t *pixel = cloud.pixel.data();
    uint8_t *rgb = color ? cloud.rgb.data() : nullptr;
    size_t n = 0;
    for (int v = 0; v < rows; ++v) {
        const float *d = disparity.ptr<float>(v);
        const uint8_t *px = color ? left.ptr<uint8_t>(v) : nullptr;
        double r[5];
        for (int i = 0; i < 5; ++i) r[i] = rowV_[i] * v + row1_[i];
        const int32_t rowStart = v * cols;
        for (int u = 0; u < cols; ++u) {
            if (!(d[u] > 0.f)) continue;
            const double dv = d[u], du = u;
            const double w = r[4] + du * col_[4] + dv * disp_[4];
            if (!(w > 0)) continue;
            const double inv = 1 / w;
            const double zr = (r[3] + du * col_[3] + dv * disp_[3]) * inv;
            if (!(zr > 0) || zr > maxRange_) continue;
            xyz[3 * n] = static_cast<float>((r[0] + du * col_[0] + dv * disp_[0]) * inv);
            xyz[3 * n + 1] = static_cast<float>((r[1] + du * col_[1] + dv * disp_[1]) * inv);
            xyz[3 * n + 2] = static_cast<float>((r[2] + du * col_[2] + dv * disp_[2]) * inv);
            pixel[n] = rowStart + u;
            if (rgb) {
                if (bgr) {
                    rgb[3 * n] = px[3 * u + 2];
                    rgb[3 * n + 1] = px[3 * u + 1];
                    rgb[3 * n + 2] = px[3 * u];
                } else {
                    rgb[3 * n] = rgb[3 * n + 1] = rgb[3 * n + 2] = px[u];
                }
            }
            ++n;
        }
    }
    cloud.xyz.resize(3 * n);
    cloud.pixel.resize(n);
    if (color) cloud.rgb.resize(3 * n);
    return valid;
}

void writePly(const std::string &path, const Cloud &cloud) {
    const size_t n = cloud.size();
    const bool color = cloud.rgb.size() == 3 * n && n > 0;
    std::ostringstream h;
    h << "ply\nformat binary_little_endian 1.0\n"
      << "comment generated by binocle\n"
      << "comment units mm\n";
    if (cloud.frame == BINOCLE_FRAME_GROUND)
        h << "comment frame ground (X lateral, right positive; Y range, forward; Z height, up)\n";
    else
        h << "comment frame camera (x right, y down, z forward along the optical axis)\n";
    h << "element vertex " << n << "\nproperty float x\nproperty float y\nproperty float z\n";
    if (color) h << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    h << "end_header\n";
    std::string bytes = h.str();
    const size_t stride = 12 + (color ? 3 : 0);
    const size_t offset = bytes.size();
    bytes.resize(offset + stride * n);
    char *out = bytes.data() + offset;
    for (size_t i = 0; i < n; ++i, out += stride) {
        std::memcpy(out, &cloud.xyz[3 * i], 12); // x86/ARM are little-endian
        if (color) std::memcpy(out + 12, &cloud.rgb[3 * i], 3);
    }
    writeFileAtomic(path, bytes);
}

Cloud readPly(const std::string &path) {
    const std::string bytes = readTextFile(path);
    const size_t end = bytes.find("end_header\n");
    if (bytes.rfind("ply\n", 0) != 0 || end == std::string::npos) throw Error(path + ": not a PLY file");
    std::istringstream header(bytes.substr(0, end));
    std::string line;
    size_t n = 0;
    bool color = false, ground = false;
    while (std::getline(header, line)) {
        if (line.rfind("element vertex ", 0) == 0) {
            int64_t count = 0;
            std::string why;
            // The data must hold them: at most as many vertices as there are bytes.
            if (!input::parseInteger(line.substr(15), count, &why, 0, static_cast<int64_t>(bytes.size())))
                throw Error(path + ": PLY header: element vertex '" + sdk::printable(line.substr(15)) + "' is not valid: " + why);
            n = static_cast<size_t>(count);
        }
        if (line == "property uchar red") color = true;
        if (line.rfind("comment frame ground", 0) == 0) ground = true;
        if (line.rfind("format ", 0) == 0 && line != "format binary_little_endian 1.0")
            throw Error(path + ": only binary_little_endian PLY is read");
    }
    const size_t stride = 12 + (color ? 3 : 0);
    const char *data = bytes.data() + end + 11;
    if (bytes.size() - (end + 11) < stride * n) throw Error(path + ": PLY data is truncated");
    Cloud c;
    c.frame = ground ? BINOCLE_FRAME_GROUND : BINOCLE_FRAME_CAMERA;
    c.xyz.resize(3 * n);
    if (color) c.rgb.resize(3 * n);
    for (size_t i = 0; i < n; ++i) {
        std::memcpy(&c.xyz[3 * i], data + i * stride, 12);
        if (color) std::memcpy(&c.rgb[3 * i], data + i * stride + 12, 3);
    }
    return c;
}

} // namespace binocle
