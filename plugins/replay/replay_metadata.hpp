// SPDX-License-Identifier: MIT
// The replay source's readers of metadata files, from their text: Middlebury calib.txt,
// KITTI calibration (a recording's frames.csv: binocle/recording.hpp; PFM: input/image_file.hpp). Every number is read strictly and
// checked before use; every failure is an sdk::Error naming the file, line and key.
// Kept apart from the source so that tests and fuzz harnesses call them directly.
#pragma once

#include <opencv2/core.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace binocle::replay {

// calib.txt: "key=value" lines; cam0/cam1 = [f 0 cx; 0 f cy; 0 0 1], baseline (mm),
// optional width, height, ndisp, doffs, vmin, vmax.
struct MiddleburyCalib {
    std::array<double, 9> cam0{}, cam1{};
    double baselineMm = 0;
    int width = 0, height = 0; // 0 when the file does not say
    std::vector<std::pair<std::string, std::string>> facts; // ndisp, doffs, vmin, vmax as written
};
MiddleburyCalib parseMiddleburyCalib(const std::string &text, const std::string &origin);

// "KEY: numbers" lines; the projection of camera i is "P<i>" or "P_rect_0<i>", the
// image size "S_rect_0<i>". Returns nullopt when the left or right projection is absent.
struct KittiCalib {
    cv::Matx34d left, right;
    double baselineMm = 0;     // from the projections: (t_left - t_right) x 1000
    int width = 0, height = 0; // 0 when the file does not say
};
std::optional<KittiCalib> parseKittiCalib(const std::string &text, const std::string &origin, int leftIndex,
                                          int rightIndex);

// The baseline (mm) an OpenCV FileStorage calibration states: its baseline_mm, else the
// length of its T; nullopt when it states neither or is not readable.
std::optional<double> calibrationBaselineMm(const std::string &yaml);

// Refuses (sdk::Error, BINOCLE_ERR_INVALID_ARGUMENT, naming both files and both values) a
// baseline that a layout's own file states and that differs from the calibration's by more
// than kBaselineTolerance (relative).
inline constexpr double kBaselineTolerance = 1e-3;
void checkBaselineAgrees(double stated_mm, const std::string &stated_file, double calibration_mm,
                         const std::string &calibration_file);

} // namespace binocle::replay
