// SPDX-License-Identifier: MIT
// The bad-input corpus's `bag` generator: small rosbag2 MCAP bags, each with one fault,
// written with Binocle::mcap (the replay plugin reads them back through `binocle`).
#include "bad_bags.hpp"

#include <binocle/mcap.hpp>
#include <binocle/ros2_messages.hpp>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace fs = std::filesystem;
using namespace binocle;

namespace {

constexpr uint32_t kWidth = 32, kHeight = 24;
constexpr double kFocalPx = 40, kBaselineM = 0.1;

ros2::CameraInfo cameraInfo(bool right, double focalPx) {
    ros2::CameraInfo c;
    c.width = kWidth;
    c.height = kHeight;
    c.d = {0, 0, 0, 0, 0};
    c.k = {focalPx, 0, kWidth / 2.0, 0, focalPx, kHeight / 2.0, 0, 0, 1};
    c.r = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    c.p = {focalPx, 0, kWidth / 2.0, right ? -focalPx * kBaselineM : 0, 0, focalPx, kHeight / 2.0, 0, 0, 0, 1, 0};
    return c;
}

} // namespace

void writeBadBag(const std::string &dir, const std::string &variant) {
    const bool oddStep = variant == "mono16_odd_step", yuv = variant == "unknown_encoding",
               badInfo = variant == "camera_info_focal_1e300", escapes = variant == "topics_with_escapes";
    if (variant != "plain" && !oddStep && !yuv && !badInfo && !escapes) throw std::invalid_argument("bag: unknown variant '" + variant + "'");
    fs::create_directories(dir);
    const std::string name = fs::path(dir).filename().string();
    mcap::Writer w((fs::path(dir) / (name + "_0.mcap")).string());
    // A topic name with a terminal escape: ESC ] 0 ; retitles a window, ESC [ 2 J clears the screen.
    const std::string ns = escapes ? "/\x1b]0;owned\x07\x1b[2Jcam" : "/cam";
    const uint16_t imageSchema = w.addSchema(ros2::Image::kType, "ros2msg", ros2::definition(ros2::Image::kType));
    const uint16_t infoSchema = w.addSchema(ros2::CameraInfo::kType, "ros2msg", ros2::definition(ros2::CameraInfo::kType));
    uint16_t image[2], info[2];
    for (int side = 0; side < 2; ++side) {
        const std::string base = ns + (side ? "/right/" : "/left/");
        image[side] = w.addChannel(imageSchema, base + "image_raw", "cdr");
        info[side] = w.addChannel(infoSchema, base + "camera_info", "cdr");
    }
    const std::string encoding = oddStep ? "mono16" : yuv ? "yuv422" : "mono8";
    const uint32_t bytesPerPixel = oddStep || yuv ? 2 : 1;
    const uint32_t step = kWidth * bytesPerPixel + (oddStep ? 1 : 0);
    std::vector<uint8_t> pixels(size_t{step} * kHeight, 100);
    uint32_t sequence = 0;
    for (int frame = 0; frame < 2; ++frame)
        for (int side = 0; side < 2; ++side) {
            // Topics with escapes: the right images 10 s after the left ones, so that no pair
            // forms and the refusal names both topics.
            const int64_t ns_ = int64_t{1000000000} * (frame + 1) + (escapes && side ? int64_t{10000000000} : 0);
            ros2::Image m;
            m.header.stamp = ros2::Time::fromNs(ns_);
            m.header.frame_id = side ? "right" : "left";
            m.width = kWidth;
            m.height = kHeight;
            m.encoding = encoding;
            m.step = step;
            m.data = pixels.data();
            m.size = pixels.size();
            const auto bytes = ros2::encode(m);
            const auto t = static_cast<uint64_t>(ns_);
            w.write(image[side], sequence++, t, t, bytes.data(), bytes.size());
            ros2::CameraInfo c = cameraInfo(side == 1, badInfo ? 1e300 : kFocalPx);
            c.header = m.header;
            const auto infoBytes = ros2::encode(c);
            w.write(info[side], sequence++, t, t, infoBytes.data(), infoBytes.size());
        }
    w.close();
}
