// SPDX-License-Identifier: MIT
// Calibration outputs: configuration name, ROS camera_info YAML, writing the set.
#include "calibration/calibration_files.hpp"

#include "files/atomic_file.hpp"
#include "core/error.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace binocle {

std::string configurationName(double baseline_mm, std::optional<double> focal_length_mm, double focal_length_px) {
    char buf[96];
    if (focal_length_mm) {
        std::snprintf(buf, sizeof buf, "B%.0f_f%.1f", std::round(baseline_mm), std::round(*focal_length_mm * 10.0) / 10.0);
        std::string s = buf;
        if (s.compare(s.size() - 2, 2, ".0") == 0) s.resize(s.size() - 2);
        return s;
    }
    std::snprintf(buf, sizeof buf, "B%.0f_f%.0fpx", std::round(baseline_mm), std::round(focal_length_px));
    return buf;
}

namespace {

void matrix(std::ostringstream &out, const char *key, const cv::Mat &m, double scaleLastColumn = 1.0, int lastColumn = -1) {
    out << key << ":\n  rows: " << m.rows << "\n  cols: " << m.cols << "\n  data: [";
    for (int r = 0; r < m.rows; ++r)
        for (int c = 0; c < m.cols; ++c) {
            const double v = m.at<double>(r, c) * (c == lastColumn ? scaleLastColumn : 1.0);
            char buf[40];
            std::snprintf(buf, sizeof buf, "%.12g", v);
            out << (r || c ? ", " : "") << buf;
        }
    out << "]\n";
}

} // namespace

std::string cameraInfoYaml(const StereoCalibration &c, bool right, const std::string &cameraName) {
    std::ostringstream out;
    out << "# ROS camera_info (camera_calibration_parsers format), written by binocle calibrate.\n"
           "# projection_matrix translation in metres (REP 103); the Binocle calibration file has millimetres.\n";
    out << "image_width: " << c.image_size.width << "\nimage_height: " << c.image_size.height << "\n";
    out << "camera_name: " << cameraName << "\n";
    matrix(out, "camera_matrix", right ? c.M2 : c.M1);
    out << "distortion_model: plumb_bob\n";
    cv::Mat d = (right ? c.D2 : c.D1).reshape(1, 1);
    if (d.cols < 5) {
        cv::Mat five = cv::Mat::zeros(1, 5, CV_64F);
        d.copyTo(five(cv::Rect(0, 0, d.cols, 1)));
        d = five;
    }
    matrix(out, "distortion_coefficients", d);
    matrix(out, "rectification_matrix", right ? c.R2 : c.R1);
    matrix(out, "projection_matrix", right ? c.P2 : c.P1, 1e-3, 3);
    return out.str();
}

CalibrationFiles CalibrationFiles::beside(const std::string &calibrationPath) {
    const fs::path p(calibrationPath);
    const fs::path dir = p.parent_path();
    const std::string stem = p.stem().string();
    CalibrationFiles f;
    f.calibration = calibrationPath;
    f.left_info = (dir / (stem + "_left.yaml")).string();
    f.right_info = (dir / (stem + "_right.yaml")).string();
    f.report = (dir / (stem + "_report.json")).string();
    return f;
}

void writeCalibrationFiles(const CalibrationFiles &files, const StereoCalibration &c, const Json &report) {
    // Everything is formatted before the first byte is written.
    const std::string left = cameraInfoYaml(c, false, "left"), right = cameraInfoYaml(c, true, "right");
    const std::string json = dumpJson(report);
    const fs::path dir = fs::path(files.calibration).parent_path();
    if (!dir.empty()) {
        std::error_code ec;
        fs::create_directories(dir, ec);
        if (ec) throw Error("--out " + files.calibration + ": cannot create the folder " + dir.string() + ": " + ec.message());
    }
    // A write that fails (a full disk) takes back the files written before it: a report
    // that reads as finished never stands beside no calibration file.
    std::vector<std::string> written;
    try {
        for (const auto &[path, text] : {std::pair<const std::string &, const std::string &>{files.report, json},
                                         {files.left_info, left},
                                         {files.right_info, right}}) {
            writeFileAtomic(path, text);
            written.push_back(path);
        }
        c.save(files.calibration);
    } catch (const Error &e) {
        std::string removed;
        for (const auto &path : written) {
            std::error_code ec;
            fs::remove(path, ec);
            removed += (removed.empty() ? "" : ", ") + path;
        }
        throw Error(std::string(e.what()) +
                    (removed.empty() ? "" : "; removed what this calibration had written before it (" + removed + ")"));
    }
}

} // namespace binocle
