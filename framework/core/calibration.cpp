// SPDX-License-Identifier: MIT
// Stereo calibration file: read, write, rectify.
#include "core/calibration.hpp"

#include "core/atomic_file.hpp"
#include "core/error.hpp"

#include <opencv2/calib3d.hpp>

namespace binocle {

double StereoCalibration::baselineMm() const { return T.empty() ? 0.0 : cv::norm(T); }

double StereoCalibration::focalLengthPx() const {
    if (!P1.empty()) return P1.at<double>(0, 0);
    return M1.empty() ? 0.0 : M1.at<double>(0, 0);
}

void StereoCalibration::computeRectification() {
    if (rectified) {
        // Already rectified: rows correspond; the reprojection matrix comes from M1 and
        // the baseline. A horizontal offset of the principal points (Middlebury's doffs)
        // is kept in Q(3,3).
        R1 = cv::Mat::eye(3, 3, CV_64F);
        R2 = cv::Mat::eye(3, 3, CV_64F);
        P1 = cv::Mat::zeros(3, 4, CV_64F);
        M1.copyTo(P1(cv::Rect(0, 0, 3, 3)));
        P2 = cv::Mat::zeros(3, 4, CV_64F);
        M2.copyTo(P2(cv::Rect(0, 0, 3, 3)));
        const double tx = T.at<double>(0);
        P2.at<double>(0, 3) = tx * M2.at<double>(0, 0);
        const double f = M1.at<double>(0, 0), cx = M1.at<double>(0, 2), cy = M1.at<double>(1, 2);
        const double cx2 = M2.at<double>(0, 2);
        Q = (cv::Mat_<double>(4, 4) << 1, 0, 0, -cx, 0, 1, 0, -cy, 0, 0, 0, f, 0, 0, -1.0 / tx, (cx - cx2) / tx);
        return;
    }
    cv::stereoRectify(M1, D1, M2, D2, image_size, R, T, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, 0, image_size);
}

namespace {

cv::Mat readMatrix(const cv::FileStorage &fs, const char *key, int rows, int cols, const std::string &origin,
                   bool required = true) {
    cv::FileNode n = fs[key];
    if (n.empty()) {
        if (required) throw Error(origin + ": calibration key '" + key + "' is missing (expected a " + std::to_string(rows) +
                                  "x" + std::to_string(cols) + " matrix)");
        return {};
    }
    cv::Mat m;
    try {
        n >> m;
    } catch (const cv::Exception &) {
        throw Error(origin + ": calibration key '" + key + "' is not an OpenCV matrix (!!opencv-matrix)");
    }
    if (m.empty()) throw Error(origin + ": calibration key '" + key + "' is empty");
    m.convertTo(m, CV_64F);
    if (rows > 0 && cols > 0 && m.total() == static_cast<size_t>(rows * cols)) m = m.reshape(1, rows);
    if ((rows > 0 && m.rows != rows) || (cols > 0 && m.cols != cols))
        throw Error(origin + ": calibration key '" + key + "' is " + std::to_string(m.rows) + "x" + std::to_string(m.cols) +
                    ", expected " + std::to_string(rows) + "x" + std::to_string(cols));
    return m;
}

} // namespace

StereoCalibration StereoCalibration::fromYaml(const std::string &text, const std::string &origin) {
    cv::FileStorage fs;
    try {
        fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    } catch (const cv::Exception &e) {
        throw Error(origin + ": not an OpenCV FileStorage YAML calibration: " + e.err);
    }
    if (!fs.isOpened()) throw Error(origin + ": not an OpenCV FileStorage YAML calibration (expected '%YAML:1.0' and keys M1, D1, ...)");
    StereoCalibration c;
    int w = 0, h = 0;
    fs["image_width"] >> w;
    fs["image_height"] >> h;
    if (w <= 0 || h <= 0)
        throw Error(origin + ": calibration keys image_width/image_height must be positive (got " + std::to_string(w) + "x" +
                    std::to_string(h) + ")");
    c.image_size = cv::Size(w, h);
    c.M1 = readMatrix(fs, "M1", 3, 3, origin);
    c.M2 = readMatrix(fs, "M2", 3, 3, origin);
    c.D1 = readMatrix(fs, "D1", 0, 0, origin, false);
    c.D2 = readMatrix(fs, "D2", 0, 0, origin, false);
    if (c.D1.empty()) c.D1 = cv::Mat::zeros(1, 5, CV_64F);
    if (c.D2.empty()) c.D2 = cv::Mat::zeros(1, 5, CV_64F);
    c.D1 = c.D1.reshape(1, 1);
    c.D2 = c.D2.reshape(1, 1);
    c.R = readMatrix(fs, "R", 3, 3, origin);
    c.T = readMatrix(fs, "T", 3, 1, origin);
    int rectified = 0;
    if (!fs["rectified"].empty()) fs["rectified"] >> rectified;
    c.rectified = rectified != 0;
    if (!fs["rms_px"].empty()) fs["rms_px"] >> c.rms_px;
    if (!fs["configuration"].empty()) fs["configuration"] >> c.configuration;
    if (c.baselineMm() <= 0) throw Error(origin + ": calibration key 'T' gives a zero baseline");
    c.computeRectification();
    return c;
}

StereoCalibration StereoCalibration::load(const std::string &path) {
    std::string text;
    try {
        text = readTextFile(path);
    } catch (const Error &e) {
        throw Error("calibration file " + path + ": " + e.what());
    }
    return fromYaml(text, path);
}

std::string StereoCalibration::toYaml() const {
    cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    fs << "image_width" << image_size.width << "image_height" << image_size.height;
    if (!configuration.empty()) fs << "configuration" << configuration;
    fs << "rectified" << (rectified ? 1 : 0);
    fs << "M1" << M1 << "D1" << D1 << "M2" << M2 << "D2" << D2 << "R" << R << "T" << T;
    if (!R1.empty()) fs << "R1" << R1 << "R2" << R2 << "P1" << P1 << "P2" << P2 << "Q" << Q;
    fs << "baseline_mm" << baselineMm() << "focal_length_px" << focalLengthPx();
    if (rms_px >= 0) fs << "rms_px" << rms_px;
    return fs.releaseAndGetString();
}

void StereoCalibration::save(const std::string &path) const { writeFileAtomic(path, toYaml()); }

StereoCalibration StereoCalibration::ideal(cv::Size size, double focal_length_px, double baseline_mm, double cx, double cy) {
    StereoCalibration c;
    c.image_size = size;
    if (cx < 0) cx = (size.width - 1) / 2.0;
    if (cy < 0) cy = (size.height - 1) / 2.0;
    c.M1 = (cv::Mat_<double>(3, 3) << focal_length_px, 0, cx, 0, focal_length_px, cy, 0, 0, 1);
    c.M2 = c.M1.clone();
    c.D1 = cv::Mat::zeros(1, 5, CV_64F);
    c.D2 = cv::Mat::zeros(1, 5, CV_64F);
    c.R = cv::Mat::eye(3, 3, CV_64F);
    c.T = (cv::Mat_<double>(3, 1) << -baseline_mm, 0, 0);
    c.rectified = true;
    c.computeRectification();
    return c;
}

} // namespace binocle
