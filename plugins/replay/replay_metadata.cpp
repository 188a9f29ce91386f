// SPDX-License-Identifier: MIT
// Readers of the replay layouts' metadata files: strict numbers, checked values.
#include "replay_metadata.hpp"

#include "input/image_file.hpp"

#include <binocle/numbers.hpp>
#include <binocle/plugin.hpp>
#include <binocle/text.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

namespace binocle::replay {

using sdk::Error;

namespace {

[[noreturn]] void refuse(const std::string &what) { throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: " + what); }

// 1e+300, 0.5, nan: as short as the value allows.
std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

std::string trim(std::string s) {
    s.erase(s.find_last_not_of(" \t") + 1);
    s.erase(0, s.find_first_not_of(" \t"));
    return s;
}

// Lines of a text file, '\r' of CRLF removed.
std::vector<std::string> linesOf(const std::string &text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        lines.push_back(std::move(line));
    }
    return lines;
}

// The numbers of "[1 0 2; 0 1 3; 0 0 1]", "1.5" or "7.2e2 0 6.0e2": strict decimals,
// finite. `where` is "<file>:<line>: '<key>'" for messages.
std::vector<double> numbersIn(std::string text, const std::string &where) {
    for (char &c : text)
        if (c == '[' || c == ']' || c == ';' || c == ',' || c == '\t') c = ' ';
    std::vector<double> out;
    std::istringstream in(text);
    for (std::string token; in >> token;) {
        double v = 0;
        std::string why;
        if (!sdk::parseDecimalReal(token, v, &why))
            refuse(where + ": '" + sdk::printable(token, 40) + "' is not a number: " + why);
        out.push_back(v);
    }
    return out;
}

int sizeValue(double v, const std::string &where) {
    if (!(v >= 1 && v <= static_cast<double>(input::kMaxImageSide)) || v != std::floor(v))
        refuse(where + " = " + number(v) + ": expected a whole number of pixels 1.." +
               std::to_string(input::kMaxImageSide));
    return static_cast<int>(v);
}

// A focal length (px) and a baseline (mm) that a triangulation can use.
void checkPinhole(const std::array<double, 9> &K, const std::string &where) {
    for (double v : K)
        if (!std::isfinite(v)) refuse(where + ": the matrix holds a value that is not finite");
    if (!(K[0] > 0) || !(K[4] > 0))
        refuse(where + ": focal lengths " + number(K[0]) + ", " + number(K[4]) + ": expected > 0 px");
    if (K[1] != 0 || K[3] != 0 || K[6] != 0 || K[7] != 0 || K[8] != 1)
        refuse(where + ": expected a camera matrix [f 0 cx; 0 f cy; 0 0 1]");
}

constexpr double kMaxBaselineMm = 1e6; // 1 km: anything larger is a unit mistake

void checkBaseline(double b, const std::string &where) {
    if (!(b > 0) || !(b <= kMaxBaselineMm))
        refuse(where + " = " + number(b) + " mm: expected a baseline > 0 and <= " + number(kMaxBaselineMm) + " mm");
}

} // namespace

MiddleburyCalib parseMiddleburyCalib(const std::string &text, const std::string &origin) {
    std::map<std::string, std::pair<std::vector<double>, int>> values; // key -> numbers, line
    const auto lines = linesOf(text);
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::string &line = lines[i];
        const int number = static_cast<int>(i + 1);
        const std::string here = origin + ":" + std::to_string(number);
        if (line.find_first_not_of(" \t") == std::string::npos) continue;
        const auto eq = line.find('=');
        if (eq == std::string::npos) refuse(here + ": '" + sdk::printable(line) + "': expected key=value");
        const std::string key = trim(line.substr(0, eq));
        auto [it, fresh] = values.try_emplace(key);
        if (!fresh)
            refuse(here + ": key '" + sdk::printable(key) + "' given twice (first on line " +
                   std::to_string(it->second.second) + ")");
        it->second = {numbersIn(line.substr(eq + 1), here + ": '" + sdk::printable(key) + "'"), number};
    }
    auto numbers = [&](const std::string &key, size_t count, bool required) -> std::vector<double> {
        auto it = values.find(key);
        if (it == values.end()) {
            if (required) refuse("Middlebury calibration '" + origin + "' has no '" + key + "' line");
            return {};
        }
        if (it->second.first.size() != count)
            refuse(origin + ":" + std::to_string(it->second.second) + ": '" + key + "' holds " +
                   std::to_string(it->second.first.size()) + " numbers; expected " + std::to_string(count));
        return it->second.first;
    };
    MiddleburyCalib c;
    const auto cam0 = numbers("cam0", 9, true);
    const auto cam1 = numbers("cam1", 9, true);
    std::copy(cam0.begin(), cam0.end(), c.cam0.begin());
    std::copy(cam1.begin(), cam1.end(), c.cam1.begin());
    checkPinhole(c.cam0, origin + ": cam0");
    checkPinhole(c.cam1, origin + ": cam1");
    c.baselineMm = numbers("baseline", 1, true)[0];
    checkBaseline(c.baselineMm, origin + ": baseline");
    const auto width = numbers("width", 1, false), height = numbers("height", 1, false);
    if (!width.empty() && !height.empty()) {
        c.width = sizeValue(width[0], origin + ": width");
        c.height = sizeValue(height[0], origin + ": height");
    }
    for (const char *key : {"ndisp", "doffs", "vmin", "vmax"}) {
        const auto v = numbers(key, 1, false);
        if (v.empty()) continue;
        std::ostringstream s;
        s << v[0];
        c.facts.emplace_back(key, s.str());
    }
    return c;
}

std::optional<KittiCalib> parseKittiCalib(const std::string &text, const std::string &origin, int leftIndex,
                                          int rightIndex) {
    std::map<std::string, std::pair<std::vector<double>, int>> values;
    const auto lines = linesOf(text);
    for (size_t i = 0; i < lines.size(); ++i) {
        const auto colon = lines[i].find(':');
        if (colon == std::string::npos) continue;
        const std::string key = trim(lines[i].substr(0, colon));
        const std::string here = origin + ":" + std::to_string(i + 1);
        // Only the keys read below are parsed: KITTI files carry others (calib_time).
        const bool wanted = key.rfind("P", 0) == 0 || key.rfind("S_rect_0", 0) == 0;
        if (!wanted) continue;
        auto [it, fresh] = values.try_emplace(key);
        if (!fresh)
            refuse(here + ": key '" + sdk::printable(key) + "' given twice (first on line " +
                   std::to_string(it->second.second) + ")");
        it->second = {numbersIn(lines[i].substr(colon + 1), here + ": '" + sdk::printable(key) + "'"),
                      static_cast<int>(i + 1)};
    }
    auto projection = [&](int i, cv::Matx34d &P) {
        for (const std::string &key : {"P" + std::to_string(i), "P_rect_0" + std::to_string(i)}) {
            auto it = values.find(key);
            if (it == values.end()) continue;
            if (it->second.first.size() != 12)
                refuse(origin + ":" + std::to_string(it->second.second) + ": '" + key + "' holds " +
                       std::to_string(it->second.first.size()) + " numbers; expected 12 (a 3x4 projection)");
            P = cv::Matx34d(it->second.first.data());
            std::array<double, 9> K{P(0, 0), P(0, 1), P(0, 2), P(1, 0), P(1, 1), P(1, 2), P(2, 0), P(2, 1), P(2, 2)};
            checkPinhole(K, origin + ":" + std::to_string(it->second.second) + ": '" + key + "'");
            return true;
        }
        return false;
    };
    KittiCalib c;
    if (!projection(leftIndex, c.left) || !projection(rightIndex, c.right)) return std::nullopt;
    // P = K [I | t]: t = K^-1 P(:,3) in metres, relative to the rectified camera 0; K is
    // upper triangular with f > 0 (checked), so tx = (P03 - cx t_z ... ) solves directly.
    auto tx = [](const cv::Matx34d &P) {
        const double tz = P(2, 3);
        const double ty = (P(1, 3) - P(1, 2) * tz) / P(1, 1);
        return (P(0, 3) - P(0, 1) * ty - P(0, 2) * tz) / P(0, 0);
    };
    c.baselineMm = (tx(c.left) - tx(c.right)) * 1000.0;
    if (!(c.baselineMm > 0))
        refuse("KITTI calibration '" + origin + "': P" + std::to_string(leftIndex) + "/P" + std::to_string(rightIndex) +
               " give a baseline of " + number(c.baselineMm) +
               " mm; expected the left camera left of the right one");
    checkBaseline(c.baselineMm, "KITTI calibration '" + origin + "': the baseline from the projections");
    if (auto s = values.find("S_rect_0" + std::to_string(leftIndex)); s != values.end()) {
        const std::string here = origin + ":" + std::to_string(s->second.second) + ": '" + s->first + "'";
        if (s->second.first.size() != 2)
            refuse(here + " holds " + std::to_string(s->second.first.size()) + " numbers; expected 2 (width height)");
        c.width = sizeValue(s->second.first[0], here + " width");
        c.height = sizeValue(s->second.first[1], here + " height");
    }
    return c;
}

namespace {

} // namespace

std::optional<double> calibrationBaselineMm(const std::string &yaml) {
    try {
        cv::FileStorage fs(yaml, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
        if (!fs.isOpened()) return std::nullopt;
        const cv::FileNode b = fs["baseline_mm"];
        if (!b.empty() && (b.isReal() || b.isInt())) return static_cast<double>(b);
        cv::Mat T;
        fs["T"] >> T;
        if (T.total() == 3) return cv::norm(T);
    } catch (const cv::Exception &) {
    }
    return std::nullopt;
}

void checkBaselineAgrees(double stated_mm, const std::string &stated_file, double calibration_mm,
                         const std::string &calibration_file) {
    if (std::abs(stated_mm - calibration_mm) <= kBaselineTolerance * std::max(std::abs(stated_mm), std::abs(calibration_mm)))
        return;
    refuse("calibration '" + sdk::printable(calibration_file, 200) + "' has a baseline of " +
           number(calibration_mm) + " mm but '" + sdk::printable(stated_file, 200) + "' states " + number(stated_mm) +
           " mm for the same images; expected one baseline (within " + number(kBaselineTolerance * 100) +
           " %): fix the calibration, or leave `calibration` unset to use the files' own");
}

} // namespace binocle::replay
