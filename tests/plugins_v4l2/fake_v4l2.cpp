// SPDX-License-Identifier: MIT
// The fake V4L2 device layer: the behaviour of the kernel's V4L2 API as the v4l2 plugin
// uses it, in memory.
#include "fake_v4l2.hpp"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <thread>

namespace binocle::v4l2 {
namespace fake {

struct State {
    std::mutex mutex;
    Camera camera;
    Counters counters;
    bool gone = false;
    bool streaming = false;
    PixFormat format;
    std::vector<std::vector<uint8_t>> buffers;
    std::vector<bool> mapped, queued;
    std::deque<uint32_t> queue; // filled in this order
    uint64_t nextFrame = 0;
};

namespace {

[[noreturn]] void fail(int err, const char *call) { throw DeviceError(err, call); }

uint32_t bytesPerPixel(uint32_t fourcc) {
    return fourcc == V4L2_PIX_FMT_GREY ? 1 : fourcc == V4L2_PIX_FMT_YUYV ? 2 : 0;
}

class FakeDevice : public Device {
public:
    FakeDevice(std::string path, std::shared_ptr<State> state) : path_(std::move(path)), s_(std::move(state)) {
        std::lock_guard<std::mutex> lock(s_->mutex);
        ++s_->counters.opened;
    }

    ~FakeDevice() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        ++s_->counters.closed;
        // Closing frees the buffers, as the kernel does.
        s_->streaming = false;
        s_->queue.clear();
        s_->buffers.clear();
        s_->mapped.clear();
        s_->queued.clear();
        s_->counters.inDriver = 0;
    }

    const std::string &path() const override { return path_; }

    Capability queryCapability() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) fail(ENODEV, "VIDIOC_QUERYCAP");
        return {s_->camera.driver, s_->camera.card, s_->camera.busInfo, s_->camera.capabilities};
    }

    std::vector<FormatDesc> formats() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) fail(ENODEV, "VIDIOC_ENUM_FMT");
        return s_->camera.formats;
    }

    // Like a driver: an offered fourcc or else the first one, the nearest offered size.
    PixFormat setFormat(const PixFormat &wanted) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) fail(ENODEV, "VIDIOC_S_FMT");
        if (s_->camera.busy || s_->streaming) fail(EBUSY, "VIDIOC_S_FMT");
        const auto &offers = s_->camera.formats;
        if (offers.empty()) fail(EINVAL, "VIDIOC_S_FMT");
        auto f = std::find_if(offers.begin(), offers.end(), [&](const FormatDesc &d) { return d.fourcc == wanted.fourcc; });
        if (f == offers.end()) f = offers.begin();
        FrameSize best = f->sizes.empty() ? FrameSize{wanted.width, wanted.height} : f->sizes.front();
        for (const FrameSize &s : f->sizes) {
            auto distance = [&](const FrameSize &a) {
                return std::abs(static_cast<int64_t>(a.width) - wanted.width) +
                       std::abs(static_cast<int64_t>(a.height) - wanted.height);
            };
            if (distance(s) < distance(best)) best = s;
        }
        PixFormat got;
        got.fourcc = f->fourcc;
        got.width = best.width;
        got.height = best.height;
        got.bytesPerLine = best.width * bytesPerPixel(f->fourcc);
        got.sizeImage = got.bytesPerLine ? got.bytesPerLine * got.height : best.width * best.height * 2;
        s_->format = got;
        return got;
    }

    double setFrameRate(double fps) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) fail(ENODEV, "VIDIOC_S_PARM");
        if (!s_->camera.canSetFrameRate) return 0;
        s_->camera.fps = fps;
        return fps;
    }

    uint32_t requestBuffers(uint32_t count) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) fail(ENODEV, "VIDIOC_REQBUFS");
        if (s_->camera.busy || s_->streaming) fail(EBUSY, "VIDIOC_REQBUFS");
        if (std::find(s_->mapped.begin(), s_->mapped.end(), true) != s_->mapped.end()) fail(EBUSY, "VIDIOC_REQBUFS");
        count = std::min<uint32_t>(count, 32);
        s_->buffers.assign(count, std::vector<uint8_t>(s_->format.sizeImage, 0));
        s_->mapped.assign(count, false);
        s_->queued.assign(count, false);
        s_->queue.clear();
        s_->counters.buffers = count;
        s_->counters.inDriver = 0;
        s_->counters.bufferMemory.clear();
        for (const auto &b : s_->buffers) s_->counters.bufferMemory.emplace_back(b.data(), b.size());
        return count;
    }

    Mapping mapBuffer(uint32_t index) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) fail(ENODEV, "VIDIOC_QUERYBUF");
        if (index >= s_->buffers.size()) fail(EINVAL, "VIDIOC_QUERYBUF");
        s_->mapped[index] = true;
        ++s_->counters.mapped;
        return {s_->buffers[index].data(), s_->buffers[index].size()};
    }

    void unmapBuffer(uint32_t index) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (index >= s_->mapped.size() || !s_->mapped[index]) fail(EINVAL, "munmap");
        s_->mapped[index] = false;
        ++s_->counters.unmapped;
    }

    void queueBuffer(uint32_t index) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) fail(ENODEV, "VIDIOC_QBUF");
        if (index >= s_->buffers.size() || s_->queued[index]) fail(EINVAL, "VIDIOC_QBUF");
        s_->queued[index] = true;
        s_->queue.push_back(index);
        ++s_->counters.queueCalls;
        ++s_->counters.inDriver;
    }

    bool dequeueBuffer(Dequeued &out) override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) fail(ENODEV, "VIDIOC_DQBUF");
        if (!s_->streaming) fail(EINVAL, "VIDIOC_DQBUF");
        if (s_->camera.stalled || s_->queue.empty()) return false; // EAGAIN
        const Camera &c = s_->camera;
        while (c.dropped.count(s_->nextFrame)) ++s_->nextFrame;
        const uint64_t n = s_->nextFrame++;
        const uint32_t index = s_->queue.front();
        s_->queue.pop_front();
        s_->queued[index] = false;
        --s_->counters.inDriver;
        std::vector<uint8_t> bytes = c.content ? c.content(n, s_->format) : std::vector<uint8_t>{};
        auto &buffer = s_->buffers[index];
        const size_t used = std::min(bytes.size(), buffer.size());
        std::copy(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(used), buffer.begin());
        out.index = index;
        out.bytesUsed = static_cast<uint32_t>(used);
        out.flags = c.corrupt.count(n) ? V4L2_BUF_FLAG_ERROR : 0;
        out.sequence = static_cast<uint32_t>(n);
        out.timestampNs = c.firstTimestampNs + static_cast<int64_t>(static_cast<double>(n) * 1e9 / c.fps);
        ++s_->counters.delivered;
        if (c.vanishAfter >= 0 && s_->counters.delivered >= static_cast<uint64_t>(c.vanishAfter)) s_->gone = true;
        return true;
    }

    Wait waitForFrame(int timeoutMs) override {
        {
            std::lock_guard<std::mutex> lock(s_->mutex);
            if (s_->gone || !s_->streaming) return Wait::Error;
            if (!s_->camera.stalled && !s_->queue.empty()) return Wait::Ready;
        }
        // Nothing will come: wait out the timeout as poll would (a test never waits long).
        std::this_thread::sleep_for(std::chrono::milliseconds(timeoutMs < 0 ? 5000 : timeoutMs));
        return Wait::Timeout;
    }

    void streamOn() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) fail(ENODEV, "VIDIOC_STREAMON");
        if (s_->buffers.empty()) fail(EINVAL, "VIDIOC_STREAMON");
        s_->streaming = true;
        ++s_->counters.streamOns;
    }

    void streamOff() override {
        std::lock_guard<std::mutex> lock(s_->mutex);
        if (s_->gone) fail(ENODEV, "VIDIOC_STREAMOFF");
        s_->streaming = false;
        for (uint32_t i : s_->queue) s_->queued[i] = false;
        s_->queue.clear();
        s_->counters.inDriver = 0;
        ++s_->counters.streamOffs;
    }

private:
    std::string path_;
    std::shared_ptr<State> s_;
};

} // namespace

void FakeSystem::reset() {
    std::lock_guard<std::mutex> lock(mutex_);
    devices_.clear();
    known_.clear();
}

void FakeSystem::add(const Camera &camera) {
    auto s = std::make_shared<State>();
    s->camera = camera;
    if (!s->camera.content) {
        const int seed = camera.seed;
        s->camera.content = [seed](uint64_t n, const PixFormat &f) {
            const cv::Mat img = pattern(static_cast<int>(f.width), static_cast<int>(f.height), n, seed);
            if (f.fourcc == V4L2_PIX_FMT_GREY) return greyBytes(img, f.bytesPerLine);
            if (f.fourcc == V4L2_PIX_FMT_YUYV) return yuyvBytes(img, 128, 128, f.bytesPerLine);
            return mjpegBytes(img);
        };
    }
    std::lock_guard<std::mutex> lock(mutex_);
    devices_[camera.path] = s;
    known_[camera.path] = s;
}

std::shared_ptr<State> FakeSystem::state(const std::string &path) const {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = known_.find(path);
    if (it == known_.end()) throw std::runtime_error("fake: no device " + path);
    return it->second;
}

void FakeSystem::change(const std::string &path, const std::function<void(Camera &)> &edit) {
    auto s = state(path);
    std::lock_guard<std::mutex> lock(s->mutex);
    edit(s->camera);
}

void FakeSystem::unplug(const std::string &path) {
    auto s = state(path);
    {
        std::lock_guard<std::mutex> lock(s->mutex);
        s->gone = true;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    devices_.erase(path);
}

Counters FakeSystem::counters(const std::string &path) const {
    auto s = state(path);
    std::lock_guard<std::mutex> lock(s->mutex);
    return s->counters;
}

std::vector<std::string> FakeSystem::listDevices() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> paths;
    for (const auto &d : devices_) paths.push_back(d.first);
    return paths;
}

std::unique_ptr<Device> FakeSystem::open(const std::string &path) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = devices_.find(path);
    if (it == devices_.end()) throw DeviceError(ENOENT, "open");
    return std::make_unique<FakeDevice>(path, it->second);
}

FakeSystem &fakeSystem() {
    static FakeSystem system;
    return system;
}

uint8_t patternValue(int x, int y, uint64_t n, int seed) {
    return static_cast<uint8_t>((3 * x + 7 * y + 11 * static_cast<int64_t>(n % 256) + 40 * seed) & 0xff);
}

cv::Mat pattern(int width, int height, uint64_t n, int seed) {
    cv::Mat m(height, width, CV_8UC1);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) m.at<uint8_t>(y, x) = patternValue(x, y, n, seed);
    return m;
}

std::vector<uint8_t> greyBytes(const cv::Mat &gray, uint32_t bytesPerLine) {
    std::vector<uint8_t> out(static_cast<size_t>(bytesPerLine) * gray.rows, 0);
    for (int y = 0; y < gray.rows; ++y) std::memcpy(&out[y * bytesPerLine], gray.ptr(y), gray.cols);
    return out;
}

std::vector<uint8_t> yuyvBytes(const cv::Mat &luma, uint8_t u, uint8_t v, uint32_t bytesPerLine) {
    std::vector<uint8_t> out(static_cast<size_t>(bytesPerLine) * luma.rows, 0);
    for (int y = 0; y < luma.rows; ++y)
        for (int x = 0; x < luma.cols; ++x) {
            uint8_t *p = &out[y * bytesPerLine + 2 * x];
            p[0] = luma.at<uint8_t>(y, x);
            p[1] = (x % 2 == 0) ? u : v; // Y0 U Y1 V
        }
    return out;
}

std::vector<uint8_t> mjpegBytes(const cv::Mat &image) {
    std::vector<uint8_t> out;
    cv::imencode(".jpg", image, out, {cv::IMWRITE_JPEG_QUALITY, 100});
    return out;
}

FormatDesc offer(uint32_t fourcc, std::vector<FrameSize> sizes) {
    FormatDesc f;
    f.fourcc = fourcc;
    f.description = fourccText(fourcc);
    f.sizes = std::move(sizes);
    return f;
}

Camera camera(const std::string &path, const std::vector<FormatDesc> &formats, int seed) {
    Camera c;
    c.path = path;
    c.formats = formats;
    c.seed = seed;
    return c;
}

} // namespace fake

System &deviceSystem() { return fake::fakeSystem(); }

} // namespace binocle::v4l2
