// SPDX-License-Identifier: MIT
// A fake IEEE-1394 bus for the videre1394 plugin's tests: stereo heads that list video
// modes, keep an SVS calibration text, fill a DMA ring with frames whose 16-bit pixels
// interleave a known left and right byte, and fail as libdc1394 does (no bus, no
// camera, a camera gone mid-capture, a frame of the wrong size).
//
// Linked instead of videre_device_dc1394.cpp: bus() returns fakeBus().
#pragma once

#include "videre_device.hpp"

#include <opencv2/core.hpp>

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace binocle::videre1394::fake {

// Frame n's left and right 8-bit images at width x height.
using Images = std::function<std::pair<cv::Mat, cv::Mat>(uint64_t n, uint32_t width, uint32_t height)>;

struct Head {
    CameraInfo info{0x00b09d0100a1b2c3ULL, 0, "Videre Design", "MDS-STH"};
    std::vector<VideoMode> modes;   // empty: standardModes()
    bool leftFirst = false;         // a Videre head sends the right imager's byte first
    std::string storedCalibration;  // "" = the head stores none
    bool calibrationUnreadable = false;
    int64_t firstTimestampUs = 1000000;
    std::set<uint64_t> corrupt;     // frames flagged corrupt
    int64_t vanishAfter = -1;       // gone once this many frames were delivered
    bool stalled = false;           // delivers nothing
    uint32_t deliverWidth = 0;      // 0: the mode's width; else frames of another size
    uint32_t padding = 0;           // bytes after each line (stride = 2 width + padding)
    Images images;                  // empty: pattern(seed 1) left, pattern(seed 2) right
};

struct Counters {
    uint32_t opened = 0, closed = 0, configured = 0;
    uint32_t setups = 0, stops = 0, stopsWithFramesOut = 0;
    uint32_t buffers = 0;  // in the DMA ring
    uint32_t inRing = 0;   // free for the camera to fill
    uint64_t delivered = 0, enqueued = 0;
    bool transmitting = false;
    std::string mode;
    double fps = 0;
    std::vector<std::pair<const uint8_t *, size_t>> bufferMemory;
};

struct HeadState; // fake_dc1394.cpp

class FakeBus : public Bus {
public:
    void reset(); // no head, a bus present
    void setNoBus(bool noBus);
    void add(const Head &head);
    void change(uint64_t guid, const std::function<void(Head &)> &edit);
    Counters counters(uint64_t guid) const;

    std::vector<CameraInfo> cameras() override;
    std::string describe() override;
    std::unique_ptr<Camera> open(const CameraInfo &camera) override;

private:
    std::shared_ptr<HeadState> state(uint64_t guid) const;
    mutable std::mutex mutex_;
    bool noBus_ = false;
    std::vector<std::shared_ptr<HeadState>> heads_;
};

FakeBus &fakeBus();

// 640x480_MONO16 (7.5, 15, 30 fps), 1280x960_MONO16 (3.75, 7.5, 15), 640x480_MONO8
// (15, 30) and format7_0 (1280x960 MONO16).
std::vector<VideoMode> standardModes();

// (5x + 3y + 13n + 70 seed) mod 256.
cv::Mat pattern(int width, int height, uint64_t n, int seed);

// One 16-bit pixel per position holding the left and right bytes, in memory order
// (left, right) when leftFirst, else (right, left); lines of `stride` bytes.
std::vector<uint8_t> interleave(const cv::Mat &left, const cv::Mat &right, bool leftFirst, uint32_t stride);

} // namespace binocle::videre1394::fake
