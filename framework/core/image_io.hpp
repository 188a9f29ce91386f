// SPDX-License-Identifier: MIT
// Disparity image formats of the field: KITTI 16-bit PNG, PFM, colourised PNG.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace binocle {

// KITTI convention: uint16 = disparity * 256, 0 = invalid. Written atomically.
void writeDisparityPng16(const std::string &path, const cv::Mat &disparity);
// Back to CV_32F, invalid pixels = -1.
cv::Mat readDisparityPng16(const std::string &path);

// Portable Float Map, little-endian, rows bottom to top as the format says. Invalid
// disparities are written as +inf (Middlebury convention).
void writePfm(const std::string &path, const cv::Mat &image);
// CV_32F (1 or 3 channels); non-finite values kept as they are.
cv::Mat readPfm(const std::string &path);

// A colour picture of a disparity map (turbo colour map, invalid pixels black);
// max_disparity <= 0 takes the largest valid value.
cv::Mat colorizeDisparity(const cv::Mat &disparity, double max_disparity = 0);

// Atomic cv::imwrite that throws binocle::Error naming the path.
void writeImage(const std::string &path, const cv::Mat &image);

} // namespace binocle
