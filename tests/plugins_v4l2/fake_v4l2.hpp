// SPDX-License-Identifier: MIT
// A fake V4L2 device layer for the v4l2 plugin's tests: devices that negotiate formats,
// hand out memory-mapped buffers, fill them with known pixels, and fail as the kernel
// does (ENOENT, EBUSY, ENODEV mid-stream, EAGAIN, EINVAL on misuse).
//
// Linked instead of v4l2_device_linux.cpp: deviceSystem() returns fakeSystem().
#pragma once

#include "v4l2_device.hpp"

#include <linux/videodev2.h>

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace binocle::v4l2::fake {

// The bytes a driver puts into a buffer for frame n (any length: a short one makes a
// frame of the wrong size).
using FrameBytes = std::function<std::vector<uint8_t>(uint64_t n, const PixFormat &format)>;

// What one fake /dev/videoN is and does.
struct Camera {
    std::string path;
    std::string card = "Fake Stereo Camera", driver = "uvcvideo", busInfo = "usb-0000:00:14.0-1";
    uint32_t capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
    std::vector<FormatDesc> formats; // S_FMT picks from these as a driver does
    bool busy = false;               // another process streams: EBUSY from S_FMT and REQBUFS
    bool canSetFrameRate = true;
    double fps = 30;                       // frame period of the time stamps (S_PARM sets it)
    int64_t firstTimestampNs = 1000000000; // time stamp of frame 0
    std::set<uint64_t> dropped;            // frame numbers never delivered
    std::set<uint64_t> corrupt;            // delivered with V4L2_BUF_FLAG_ERROR
    int64_t vanishAfter = -1;              // unplugged once this many frames were delivered
    bool stalled = false;                  // delivers nothing: poll times out
    int seed = 0;                          // varies the default pattern between devices
    FrameBytes content;                    // default: pattern() in the negotiated format
};

// What the fake saw of one device.
struct Counters {
    uint32_t opened = 0, closed = 0;
    uint32_t queueCalls = 0, streamOns = 0, streamOffs = 0, mapped = 0, unmapped = 0;
    uint32_t buffers = 0;  // granted by the last VIDIOC_REQBUFS
    uint32_t inDriver = 0; // queued and not yet dequeued
    uint64_t delivered = 0;
    std::vector<std::pair<const uint8_t *, size_t>> bufferMemory; // where the buffers live
};

struct State; // one device's runtime state (fake_v4l2.cpp)

class FakeSystem : public System {
public:
    // Forgets every device (call at the start of each test).
    void reset();
    void add(const Camera &camera);
    // Changes a device's behaviour, e.g. to stall it while streaming.
    void change(const std::string &path, const std::function<void(Camera &)> &edit);
    // The device vanishes now: its node disappears, calls on it fail with ENODEV.
    void unplug(const std::string &path);
    Counters counters(const std::string &path) const;

    std::vector<std::string> listDevices() override;
    std::unique_ptr<Device> open(const std::string &path) override;

private:
    std::shared_ptr<State> state(const std::string &path) const;
    mutable std::mutex mutex_;
    std::map<std::string, std::shared_ptr<State>> devices_; // present
    std::map<std::string, std::shared_ptr<State>> known_;   // present or unplugged, for counters
};

FakeSystem &fakeSystem();

// ---- Frame content ------------------------------------------------------------------

// The default picture of frame n: value (3x + 7y + 11n + 40 seed) mod 256.
uint8_t patternValue(int x, int y, uint64_t n, int seed);
cv::Mat pattern(int width, int height, uint64_t n, int seed);

// Packs images the way a driver lays them out.
std::vector<uint8_t> greyBytes(const cv::Mat &gray, uint32_t bytesPerLine);
std::vector<uint8_t> yuyvBytes(const cv::Mat &luma, uint8_t u, uint8_t v, uint32_t bytesPerLine);
std::vector<uint8_t> mjpegBytes(const cv::Mat &image); // cv::imencode, quality 100

// A UVC-like device offering `formats` ("GREY 64x48" ...).
Camera camera(const std::string &path, const std::vector<FormatDesc> &formats, int seed = 0);
FormatDesc offer(uint32_t fourcc, std::vector<FrameSize> sizes);

} // namespace binocle::v4l2::fake
