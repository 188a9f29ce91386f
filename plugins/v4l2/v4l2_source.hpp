// SPDX-License-Identifier: MIT
// v4l2: the StereoSource the plugin exports: USB stereo rigs on Video4Linux2, either two
// devices (one per imager) or one device delivering side-by-side frames.
//
// Compiled into the plugin with the libv4l2 device layer and into the tests with a
// fake one (see v4l2_device.hpp); nothing here touches the kernel directly.
#pragma once

#include "v4l2_device.hpp"

#include <binocle/plugin.hpp>

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace binocle::v4l2 {

struct Settings {
    bool sideBySide = false;
    std::string deviceLeft = "/dev/video0";
    std::string deviceRight = "/dev/video1";
    bool swapHalves = false;
    uint32_t fourcc = 0; // V4L2_PIX_FMT_GREY, _YUYV or _MJPEG
    bool bgr = false;    // deliver BGR8 instead of GRAY8
    uint32_t width = 640, height = 480;
    double fps = 30;
    uint32_t bufferCount = 4;
    double pairToleranceMs = 0; // 0: half the frame period
};

class Stream; // one opened device and its buffers (v4l2_stream.hpp)

class V4l2Source : public sdk::StereoSource {
public:
    static std::vector<binocle_param_desc> parameters();
    // Opens the device(s) and negotiates the format; buffers are requested at start.
    V4l2Source(const sdk::CheckedParams &params, sdk::Host &host);
    ~V4l2Source() override;

    void start() override;
    void stop() override;
    std::unique_ptr<sdk::Frame> grab(int32_t timeout_ms) override;
    std::string statistics() override;
    static std::string enumerateDevices(sdk::Host &host);

private:
    std::shared_ptr<Stream> openStream(const std::string &path, const std::string &role);
    Dequeued fetch(size_t which, int64_t deadlineNs, int32_t timeoutMs);
    std::unique_ptr<sdk::Frame> makeFrame(const std::array<std::optional<Dequeued>, 2> &taken);
    bool zeroCopy() const;

    sdk::Host host_;
    Settings settings_;
    std::vector<std::shared_ptr<Stream>> streams_; // [left, right] or [the one device]
    std::array<std::optional<Dequeued>, 2> pending_; // dequeued, waiting for a partner
    int64_t toleranceNs_ = 0;
    bool started_ = false;
    uint64_t sequence_ = 0;
};

} // namespace binocle::v4l2
