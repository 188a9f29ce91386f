// SPDX-License-Identifier: MIT
// videre1394: SVS calibration text -> OpenCV FileStorage YAML calibration.
#include "svs_calibration.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace binocle::videre1394 {
namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

std::string trim(const std::string &s) {
    const auto b = s.find_first_not_of(" \t\r\n");
    if (b == std::string::npos) return "";
    return s.substr(b, s.find_last_not_of(" \t\r\n") + 1 - b);
}

bool isNumber(const std::string &s, double &v) {
    try {
        size_t used = 0;
        v = std::stod(s, &used);
        return used == s.size() && std::isfinite(v);
    } catch (const std::logic_error &) {
        return false;
    }
}

std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

} // namespace

SvsCalibration parseSvs(const std::string &text) {
    // section -> key -> value; only the sections and keys used below are kept.
    std::map<std::string, std::map<std::string, double>> values;
    const std::map<std::string, std::vector<std::string>> wanted{
        {"left camera", {"pwidth", "pheight", "f", "fy", "cx", "cy", "kappa1", "kappa2", "kappa3", "tau1", "tau2"}},
        {"right camera", {"pwidth", "pheight", "f", "fy", "cx", "cy", "kappa1", "kappa2", "kappa3", "tau1", "tau2"}},
        {"external", {"tx", "ty", "tz", "rx", "ry", "rz"}},
        {"image", {"width", "height"}}};

    std::istringstream in(text);
    std::string line, section;
    bool sawSection = false;
    for (int number = 1; std::getline(in, line); ++number) {
        line = trim(line);
        if (line.empty() || line[0] == '#' || line[0] == ';') continue;
        if (line.front() == '[') {
            if (line.back() != ']')
                throw std::invalid_argument("line " + std::to_string(number) + ": '" + line + "': expected [section]");
            section = lower(trim(line.substr(1, line.size() - 2)));
            sawSection = true;
            continue;
        }
        std::istringstream words(line);
        std::string key, value, extra;
        words >> key >> value >> extra;
        double v = 0;
        if (isNumber(key, v)) continue; // a row of a matrix (proj, rect): not used
        auto keys = wanted.find(section);
        if (keys == wanted.end()) continue;
        const std::string k = lower(key);
        if (std::find(keys->second.begin(), keys->second.end(), k) == keys->second.end()) continue;
        if (!isNumber(value, v) || !extra.empty())
            throw std::invalid_argument("line " + std::to_string(number) + ": [" + section + "] " + key + " '" +
                                        trim(line.substr(key.size())) + "' is not a number");
        values[section][k] = v;
    }
    if (!sawSection) throw std::invalid_argument("no [section] at all: not an SVS calibration text");

    auto get = [&](const std::string &sec, const std::string &key, bool required, double def = 0) {
        auto s = values.find(sec);
        if (s != values.end()) {
            auto k = s->second.find(key);
            if (k != s->second.end()) return k->second;
        }
        if (required) throw std::invalid_argument("[" + sec + "] has no '" + key + "'");
        return def;
    };
    auto camera = [&](const std::string &sec) {
        SvsCamera c;
        c.f = get(sec, "f", true);
        c.fy = get(sec, "fy", false, c.f);
        c.cx = get(sec, "cx", true);
        c.cy = get(sec, "cy", true);
        c.kappa1 = get(sec, "kappa1", false);
        c.kappa2 = get(sec, "kappa2", false);
        c.kappa3 = get(sec, "kappa3", false);
        c.tau1 = get(sec, "tau1", false);
        c.tau2 = get(sec, "tau2", false);
        c.width = get(sec, "pwidth", false, get("image", "width", false));
        c.height = get(sec, "pheight", false, get("image", "height", false));
        if (c.width <= 0 || c.height <= 0)
            throw std::invalid_argument("[" + sec + "] has no image size (pwidth/pheight, or width/height in [image])");
        if (c.f <= 0 || c.fy <= 0)
            throw std::invalid_argument("[" + sec + "] f " + number(c.f) + ": expected a focal length > 0 px");
        return c;
    };
    SvsCalibration cal;
    cal.left = camera("left camera");
    cal.right = camera("right camera");
    if (cal.left.width != cal.right.width || cal.left.height != cal.right.height)
        throw std::invalid_argument("[left camera] is " + number(cal.left.width) + "x" + number(cal.left.height) +
                                    " but [right camera] is " + number(cal.right.width) + "x" + number(cal.right.height));
    cal.tx = get("external", "tx", true);
    cal.ty = get("external", "ty", false);
    cal.tz = get("external", "tz", false);
    cal.rx = get("external", "rx", false);
    cal.ry = get("external", "ry", false);
    cal.rz = get("external", "rz", false);
    if (std::sqrt(cal.tx * cal.tx + cal.ty * cal.ty + cal.tz * cal.tz) <= 0)
        throw std::invalid_argument("[external] Tx Ty Tz give a zero baseline");
    return cal;
}

std::string calibrationYaml(const SvsCalibration &svs, int width, int height, const std::string &configuration) {
    const double sx = width / svs.left.width, sy = height / svs.left.height;
    if (std::abs(sx - sy) > 1e-6 * std::max(sx, sy))
        throw std::invalid_argument("it was made at " + number(svs.left.width) + "x" + number(svs.left.height) +
                                    ", which does not scale to the delivered " + std::to_string(width) + "x" +
                                    std::to_string(height));
    // A pixel's centre keeps its place when the image is scaled: (c + 0.5) s - 0.5.
    auto intrinsics = [&](const SvsCamera &c) {
        return cv::Mat(cv::Matx33d(c.f * sx, 0, (c.cx + 0.5) * sx - 0.5, 0, c.fy * sy, (c.cy + 0.5) * sy - 0.5, 0, 0, 1));
    };
    auto distortion = [](const SvsCamera &c) {
        return cv::Mat(cv::Matx<double, 1, 5>(c.kappa1, c.kappa2, c.tau1, c.tau2, c.kappa3));
    };
    cv::Mat R;
    cv::Rodrigues(cv::Mat(cv::Vec3d(svs.rx, svs.ry, svs.rz)), R);
    const cv::Mat T(cv::Vec3d(svs.tx, svs.ty, svs.tz));
    const cv::Mat M1 = intrinsics(svs.left);

    cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    fs << "image_width" << width << "image_height" << height;
    if (!configuration.empty()) fs << "configuration" << configuration;
    fs << "rectified" << 0;
    fs << "M1" << M1 << "D1" << distortion(svs.left);
    fs << "M2" << intrinsics(svs.right) << "D2" << distortion(svs.right);
    fs << "R" << R << "T" << T;
    fs << "baseline_mm" << cv::norm(T) << "focal_length_px" << M1.at<double>(0, 0);
    return fs.releaseAndGetString();
}

} // namespace binocle::videre1394
