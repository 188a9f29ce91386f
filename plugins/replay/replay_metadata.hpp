// SPDX-License-Identifier: MIT
// The replay source's readers of metadata files, from their text: Middlebury calib.txt,
// KITTI calibration, a recording's frames.csv, PFM. Every number is read strictly and
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

// frames.csv of a recording: a header naming sequence, timestamp_left_ns,
// timestamp_right_ns, left, right (any order), then one line per pair. Image paths must
// stay inside the recording folder. An incomplete last line (the recorder stopped while
// writing it) is dropped and said in `droppedLast`; a bad line elsewhere throws.
struct RecordedPair {
    int64_t sequence = 0, timestampLeftNs = 0, timestampRightNs = 0;
    std::string left, right; // relative to the folder
    int line = 0;
};
struct RecordingIndex {
    std::vector<RecordedPair> pairs;
    std::string droppedLast; // why the last line was ignored; empty when it was not
};
RecordingIndex parseFramesCsv(const std::string &text, const std::string &origin);

// Portable Float Map from its bytes: "Pf" (1 channel) or "PF" (3 channels), negative
// scale = little-endian, rows stored bottom to top. The header is checked against the
// image limits and the file's size before anything is allocated. Returns CV_32FC1 or
// CV_32FC3, top row first, values as stored (inf stays inf).
cv::Mat decodePfm(const uint8_t *data, size_t size, const std::string &origin);

} // namespace binocle::replay
