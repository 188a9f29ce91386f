// SPDX-License-Identifier: MIT
// File helpers of the replay source: glob patterns, natural order, PFM, disparity ground truth.
#pragma once

#include <opencv2/core.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace binocle::replay {

// True when the text holds a glob wildcard: *, ? or [.
bool hasWildcard(const std::string &text);

// Shell-style match of one path component: * (any run), ? (one character), [abc],
// [a-z], [!a] or [^a]. A leading '.' in `name` must be matched literally.
bool wildcardMatch(const std::string &pattern, const std::string &name);

// "left_2" < "left_10": runs of digits compare by value, the rest byte by byte.
bool naturalLess(const std::string &a, const std::string &b);

// Every existing path (file or folder) that the pattern names, in natural order.
// Wildcards may stand in any component ("/data/*/im0.png"). A pattern without
// wildcards yields itself when it exists.
std::vector<std::filesystem::path> globPaths(const std::string &pattern);

// The entries of a folder, in natural order; regular files or folders only.
std::vector<std::filesystem::path> listFolder(const std::filesystem::path &folder, bool folders);

// Portable Float Map through Binocle's one PFM path (input::readPfm: header checked, the
// scale's sign is the byte order, its magnitude is not applied): CV_32FC1 or CV_32FC3, top
// row first, values as stored (inf stays inf). Throws sdk::Error naming the file.
cv::Mat readPfm(const std::filesystem::path &path);

// A disparity ground truth, decoded by format:
//   16-bit PNG  value / 256 (KITTI), 0 = unknown
//   8-bit image value, 0 = unknown
//   PFM / float value, inf, NaN and 0 = unknown; a negative value is refused
// then multiplied by `scale`. A grey palette PNG is read as its grey values.
// disparity: CV_32F, -1 where unknown; valid: CV_8U 0/255. With `imageWidth` > 0, a known
// disparity >= imageWidth is refused (it cannot be a disparity of the image). Throws
// sdk::Error naming the file.
struct GroundTruth {
    cv::Mat disparity;
    cv::Mat valid;
};
GroundTruth readGroundTruth(const std::filesystem::path &path, double scale, int imageWidth = 0);

// The text of a small metadata file (at most 16 MiB); a folder, a missing or a larger file is
// refused (sdk::Error naming `what` and the path).
std::string readText(const std::filesystem::path &path, const std::string &what);

// 'path' in single quotes, as every replay message names a file or folder.
std::string inQuotes(const std::filesystem::path &p);
// An image file's size from its header (input::inspectImage), else from decoding it.
cv::Size imageSizeOf(const std::filesystem::path &path);
// By its extension: png, jpg, jpeg, bmp, tif, tiff, pgm, ppm, pfm, webp.
bool isImageFile(const std::filesystem::path &p);

} // namespace binocle::replay
