// SPDX-License-Identifier: MIT
// The fake IEEE-1394 bus: libdc1394's camera, capture and DMA ring behaviour, in memory.
#include "fake_dc1394.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <thread>

namespace binocle::videre1394 {
namespace fake {

struct HeadState {
    std::mutex mutex;
    Head head;
    Counters counters;
    bool gone = false;
    bool capturing = false;
    VideoMode mode;
    std::vector<std::vector<uint8_t>> ring;
    std::vector<bool> out; // dequeued and not yet enqueued
    uint32_t next = 0;     // slot the camera fills next
    uint64_t frame = 0;
};

namespace {

using Kind = DeviceError::Kind;

class FakeCamera : public Camera {
public:
    explicit FakeCamera(std::shared_ptr<HeadState> s) : s_(std::move(s)) {
        std::lock_guard<std::mutex> lock(s_->mutex);
        ++s_->counters.opened;
    }

    ~FakeCamera() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        ++s_->counters.closed;
        s_->counters.transmitting = false;
        if (s_->capturing) stopLocked();
    }

    CameraInfo info() const override { return s_->head.info; }

    std::vector<VideoMode> modes() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) throw DeviceError(Kind::Gone, "dc1394_video_get_supported_modes: Camera not found");
        return s_->head.modes;
    }

    void configure(const VideoMode &mode, double fps, uint32_t) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        const auto &modes = s_->head.modes;
        if (std::none_of(modes.begin(), modes.end(), [&](const VideoMode &m) { return m.id == mode.id; }))
            throw DeviceError(Kind::Failed, "dc1394_video_set_mode: Invalid video mode");
        s_->mode = mode;
        ++s_->counters.configured;
        s_->counters.mode = mode.name;
        s_->counters.fps = fps;
    }

    std::string readStoredCalibration() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->head.calibrationUnreadable)
            throw DeviceError(Kind::Failed, "dc1394_get_control_register (stored calibration): Generic failure");
        return s_->head.storedCalibration;
    }

    void setupCapture(uint32_t buffers) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->capturing) throw DeviceError(Kind::Failed, "dc1394_capture_setup: Capture is already set up");
        const size_t bytes = static_cast<size_t>(stride()) * s_->mode.height;
        s_->ring.assign(buffers, std::vector<uint8_t>(bytes, 0));
        s_->out.assign(buffers, false);
        s_->capturing = true;
        ++s_->counters.setups;
        s_->counters.buffers = buffers;
        s_->counters.inRing = buffers;
        s_->counters.bufferMemory.clear();
        for (const auto &b : s_->ring) s_->counters.bufferMemory.emplace_back(b.data(), b.size());
    }

    void stopCapture() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->capturing) stopLocked();
    }

    void startTransmission() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) throw DeviceError(Kind::Gone, "dc1394_video_set_transmission: Camera not found");
        s_->counters.transmitting = true;
    }

    void stopTransmission() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) throw DeviceError(Kind::Gone, "dc1394_video_set_transmission: Camera not found");
        s_->counters.transmitting = false;
    }

    bool waitForFrame(int timeoutMs) override {
        {
            std::lock_guard<std::mutex> lock(s_->mutex);
            if (s_->gone) throw DeviceError(Kind::Gone, "poll on the capture reported an error");
            if (ready()) return true;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(timeoutMs < 0 ? 5000 : timeoutMs));
        return false;
    }

    bool dequeue(RawFrame &out) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) throw DeviceError(Kind::Gone, "dc1394_capture_dequeue: Failed to read from file descriptor");
        if (!s_->capturing) throw DeviceError(Kind::Failed, "dc1394_capture_dequeue: Capture is not set");
        if (!ready()) return false;
        const Head &h = s_->head;
        const uint32_t slot = s_->next;
        s_->next = (s_->next + 1) % static_cast<uint32_t>(s_->ring.size());
        const uint64_t n = s_->frame++;
        const uint32_t w = h.deliverWidth ? h.deliverWidth : s_->mode.width, ht = s_->mode.height;
        const auto images = h.images ? h.images(n, w, ht)
                                     : std::make_pair(pattern(static_cast<int>(w), static_cast<int>(ht), n, 1),
                                                      pattern(static_cast<int>(w), static_cast<int>(ht), n, 2));
        const uint32_t lineBytes = 2 * w + h.padding;
        const std::vector<uint8_t> bytes = interleave(images.first, images.second, h.leftFirst, lineBytes);
        auto &buffer = s_->ring[slot];
        if (buffer.size() < bytes.size()) buffer.resize(bytes.size()); // a wrong-size camera
        std::copy(bytes.begin(), bytes.end(), buffer.begin());
        s_->out[slot] = true;
        --s_->counters.inRing;
        ++s_->counters.delivered;
        out.image = buffer.data();
        out.width = w;
        out.height = ht;
        out.stride = lineBytes;
        out.bitsPerPixel = 16;
        out.imageBytes = static_cast<uint64_t>(lineBytes) * ht;
        out.timestampUs = static_cast<uint64_t>(h.firstTimestampUs) +
                          static_cast<uint64_t>(static_cast<double>(n) * 1e6 / (s_->counters.fps > 0 ? s_->counters.fps : 15));
        out.framesBehind = 0; // filled only when asked: never behind
        out.corrupt = h.corrupt.count(n) != 0;
        out.handle = reinterpret_cast<void *>(static_cast<uintptr_t>(slot) + 1);
        if (h.vanishAfter >= 0 && s_->counters.delivered >= static_cast<uint64_t>(h.vanishAfter)) s_->gone = true;
        return true;
    }

    void enqueue(const RawFrame &frame) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) throw DeviceError(Kind::Gone, "dc1394_capture_enqueue: Camera not found");
        const auto slot = static_cast<uint32_t>(reinterpret_cast<uintptr_t>(frame.handle) - 1);
        if (!s_->capturing || slot >= s_->out.size() || !s_->out[slot])
            throw DeviceError(Kind::Failed, "dc1394_capture_enqueue: the frame was not dequeued");
        s_->out[slot] = false;
        ++s_->counters.inRing;
        ++s_->counters.enqueued;
    }

private:
    uint32_t stride() const { return 2 * s_->mode.width + s_->head.padding; }

    // The camera fills the next slot of the ring if the application gave it back.
    bool ready() const {
        return s_->capturing && s_->counters.transmitting && !s_->head.stalled && !s_->ring.empty() &&
               !s_->out[s_->next];
    }

    void stopLocked() {
        if (std::find(s_->out.begin(), s_->out.end(), true) != s_->out.end()) ++s_->counters.stopsWithFramesOut;
        s_->capturing = false;
        s_->ring.clear();
        s_->out.clear();
        s_->next = 0;
        s_->counters.inRing = 0;
        ++s_->counters.stops;
    }

    std::shared_ptr<HeadState> s_;
};

} // namespace

void FakeBus::reset() {
    std::lock_guard<std::mutex> lock(mutex_);
    noBus_ = false;
    heads_.clear();
}

void FakeBus::setNoBus(bool noBus) {
    std::lock_guard<std::mutex> lock(mutex_);
    noBus_ = noBus;
}

void FakeBus::add(const Head &head) {
    auto s = std::make_shared<HeadState>();
    s->head = head;
    if (s->head.modes.empty()) s->head.modes = standardModes();
    std::lock_guard<std::mutex> lock(mutex_);
    heads_.push_back(s);
}

std::shared_ptr<HeadState> FakeBus::state(uint64_t guid) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto &h : heads_)
        if (h->head.info.guid == guid) return h;
    throw std::runtime_error("fake: no head with that GUID");
}

void FakeBus::change(uint64_t guid, const std::function<void(Head &)> &edit) {
    auto s = state(guid);
    std::lock_guard<std::mutex> lock(s->mutex);
    edit(s->head);
}

Counters FakeBus::counters(uint64_t guid) const {
    auto s = state(guid);
    std::lock_guard<std::mutex> lock(s->mutex);
    return s->counters;
}

std::vector<CameraInfo> FakeBus::cameras() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (noBus_) throw DeviceError(DeviceError::Kind::NoBus, "no IEEE-1394 bus found (dc1394_new failed)");
    std::vector<CameraInfo> out;
    for (const auto &h : heads_) out.push_back(h->head.info);
    return out;
}

std::string FakeBus::describe() { return "fake bus with no camera"; }

std::unique_ptr<Camera> FakeBus::open(const CameraInfo &camera) {
    return std::make_unique<FakeCamera>(state(camera.guid));
}

FakeBus &fakeBus() {
    static FakeBus b;
    return b;
}

std::vector<VideoMode> standardModes() {
    auto mode = [](uint32_t id, std::string name, uint32_t w, uint32_t h, std::string coding, uint32_t bits, bool f7,
                   std::vector<double> rates) {
        VideoMode m;
        m.id = id;
        m.name = std::move(name);
        m.width = w;
        m.height = h;
        m.coding = std::move(coding);
        m.bitsPerPixel = bits;
        m.format7 = f7;
        m.framerates = std::move(rates);
        return m;
    };
    // Ids as in libdc1394's dc1394video_mode_t; only their distinctness matters here.
    return {mode(70, "640x480_MONO16", 640, 480, "MONO16", 16, false, {7.5, 15, 30}),
            mode(85, "1280x960_MONO16", 1280, 960, "MONO16", 16, false, {3.75, 7.5, 15}),
            mode(69, "640x480_MONO8", 640, 480, "MONO8", 8, false, {15, 30}),
            mode(88, "format7_0", 1280, 960, "MONO16", 16, true, {})};
}

cv::Mat pattern(int width, int height, uint64_t n, int seed) {
    cv::Mat m(height, width, CV_8UC1);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            m.at<uint8_t>(y, x) = static_cast<uint8_t>((5 * x + 3 * y + 13 * static_cast<int64_t>(n % 256) + 70 * seed) & 0xff);
    return m;
}

std::vector<uint8_t> interleave(const cv::Mat &left, const cv::Mat &right, bool leftFirst, uint32_t stride) {
    std::vector<uint8_t> out(static_cast<size_t>(stride) * left.rows, 0);
    for (int y = 0; y < left.rows; ++y)
        for (int x = 0; x < left.cols; ++x) {
            uint8_t *p = &out[static_cast<size_t>(y) * stride + 2 * x];
            p[leftFirst ? 0 : 1] = left.at<uint8_t>(y, x);
            p[leftFirst ? 1 : 0] = right.at<uint8_t>(y, x);
        }
    return out;
}

} // namespace fake

Bus &bus() { return fake::fakeBus(); }

} // namespace binocle::videre1394
