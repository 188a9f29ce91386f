// SPDX-License-Identifier: MIT
// v4l2: the device layer of the plugin, on libv4l2 (v4l2_open, v4l2_ioctl, v4l2_mmap)
// and poll(2).
#include "v4l2_device.hpp"

#include <libv4l2.h>
#include <linux/videodev2.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <map>
#include <poll.h>
#include <sys/mman.h>

namespace binocle::v4l2 {
namespace {

// A capture buffer descriptor for memory-mapped I/O, for QUERYBUF, QBUF and DQBUF.
v4l2_buffer mmapBuffer(uint32_t index = 0) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = index;
    return buf;
}

std::string fixedText(const uint8_t *s, size_t n) {
    const char *c = reinterpret_cast<const char *>(s);
    return std::string(c, strnlen(c, n));
}

class LinuxDevice : public Device {
public:
    explicit LinuxDevice(const std::string &path) : path_(path) {
        fd_ = v4l2_open(path.c_str(), O_RDWR | O_NONBLOCK);
        if (fd_ < 0) throw DeviceError(errno, "open");
    }

    ~LinuxDevice() override {
        for (const auto &m : mapped_) v4l2_munmap(m.second.data, m.second.length);
        v4l2_close(fd_);
    }

    LinuxDevice(const LinuxDevice &) = delete;
    LinuxDevice &operator=(const LinuxDevice &) = delete;

    const std::string &path() const override { return path_; }

    Capability queryCapability() override {
        v4l2_capability cap{};
        ioctlOrThrow(VIDIOC_QUERYCAP, &cap, "VIDIOC_QUERYCAP");
        Capability c;
        c.driver = fixedText(cap.driver, sizeof(cap.driver));
        c.card = fixedText(cap.card, sizeof(cap.card));
        c.busInfo = fixedText(cap.bus_info, sizeof(cap.bus_info));
        c.capabilities = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
        return c;
    }

    std::vector<FormatDesc> formats() override {
        std::vector<FormatDesc> out;
        for (uint32_t index = 0;; ++index) {
            v4l2_fmtdesc desc{};
            desc.index = index;
            desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
            if (!tryIoctl(VIDIOC_ENUM_FMT, &desc, "VIDIOC_ENUM_FMT")) break; // EINVAL: end of list
            FormatDesc f;
            f.fourcc = desc.pixelformat;
            f.description = fixedText(desc.description, sizeof(desc.description));
            f.emulated = (desc.flags & V4L2_FMT_FLAG_EMULATED) != 0;
            f.sizes = frameSizes(desc.pixelformat);
            out.push_back(std::move(f));
        }
        return out;
    }

    PixFormat setFormat(const PixFormat &wanted) override {
        v4l2_format fmt{};
        fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        fmt.fmt.pix.width = wanted.width;
        fmt.fmt.pix.height = wanted.height;
        fmt.fmt.pix.pixelformat = wanted.fourcc;
        fmt.fmt.pix.field = V4L2_FIELD_NONE;
        ioctlOrThrow(VIDIOC_S_FMT, &fmt, "VIDIOC_S_FMT");
        PixFormat got;
        got.fourcc = fmt.fmt.pix.pixelformat;
        got.width = fmt.fmt.pix.width;
        got.height = fmt.fmt.pix.height;
        got.bytesPerLine = fmt.fmt.pix.bytesperline;
        got.sizeImage = fmt.fmt.pix.sizeimage;
        return got;
    }

    double setFrameRate(double fps) override {
        v4l2_streamparm parm{};
        parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        if (!tryIoctl(VIDIOC_G_PARM, &parm, "VIDIOC_G_PARM")) return 0;
        if (!(parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) return 0;
        // Time per frame as a fraction: 1000 / (fps * 1000) keeps rates like 7.5 exact.
        parm.parm.capture.timeperframe.numerator = 1000;
        parm.parm.capture.timeperframe.denominator = static_cast<uint32_t>(std::lround(fps * 1000.0));
        ioctlOrThrow(VIDIOC_S_PARM, &parm, "VIDIOC_S_PARM");
        const v4l2_fract &t = parm.parm.capture.timeperframe;
        return t.numerator ? static_cast<double>(t.denominator) / t.numerator : 0.0;
    }

    uint32_t requestBuffers(uint32_t count) override {
        v4l2_requestbuffers req{};
        req.count = count;
        req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        req.memory = V4L2_MEMORY_MMAP;
        ioctlOrThrow(VIDIOC_REQBUFS, &req, "VIDIOC_REQBUFS");
        return req.count;
    }

    Mapping mapBuffer(uint32_t index) override {
        v4l2_buffer buf = mmapBuffer(index);
        ioctlOrThrow(VIDIOC_QUERYBUF, &buf, "VIDIOC_QUERYBUF");
        void *p = v4l2_mmap(nullptr, buf.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, buf.m.offset);
        if (p == MAP_FAILED) throw DeviceError(errno, "mmap");
        Mapping m{static_cast<uint8_t *>(p), buf.length};
        mapped_[index] = m;
        return m;
    }

    void unmapBuffer(uint32_t index) override {
        auto it = mapped_.find(index);
        if (it == mapped_.end()) return;
        const int rc = v4l2_munmap(it->second.data, it->second.length);
        mapped_.erase(it);
        if (rc != 0) throw DeviceError(errno, "munmap");
    }

    void queueBuffer(uint32_t index) override {
        v4l2_buffer buf = mmapBuffer(index);
        ioctlOrThrow(VIDIOC_QBUF, &buf, "VIDIOC_QBUF");
    }

    bool dequeueBuffer(Dequeued &out) override {
        v4l2_buffer buf = mmapBuffer();
        if (retrying(VIDIOC_DQBUF, &buf) == -1) {
            if (errno == EAGAIN) return false;
            throw DeviceError(errno, "VIDIOC_DQBUF");
        }
        out.index = buf.index;
        out.bytesUsed = buf.bytesused;
        out.flags = buf.flags;
        out.sequence = buf.sequence;
        out.timestampNs = static_cast<int64_t>(buf.timestamp.tv_sec) * 1000000000LL +
                          static_cast<int64_t>(buf.timestamp.tv_usec) * 1000LL;
        return true;
    }

    Wait waitForFrame(int timeoutMs) override {
        using Clock = std::chrono::steady_clock;
        const auto deadline = Clock::now() + std::chrono::milliseconds(std::max(timeoutMs, 0));
        for (;;) {
            pollfd p{fd_, POLLIN, 0};
            int wait = timeoutMs;
            if (timeoutMs >= 0) {
                const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
                wait = static_cast<int>(std::max<int64_t>(left, 0));
            }
            const int rc = poll(&p, 1, wait);
            if (rc < 0) {
                if (errno == EINTR) continue;
                throw DeviceError(errno, "poll");
            }
            if (rc == 0) return Wait::Timeout;
            if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) return Wait::Error;
            if (p.revents & POLLIN) return Wait::Ready;
        }
    }

    void streamOn() override {
        int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        ioctlOrThrow(VIDIOC_STREAMON, &type, "VIDIOC_STREAMON");
    }

    void streamOff() override {
        int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        ioctlOrThrow(VIDIOC_STREAMOFF, &type, "VIDIOC_STREAMOFF");
    }

private:
    // v4l2_ioctl, again when a signal interrupted it; -1 with errno on failure.
    int retrying(unsigned long request, void *arg) {
        int rc;
        do rc = v4l2_ioctl(fd_, request, arg);
        while (rc == -1 && errno == EINTR);
        return rc;
    }

    void ioctlOrThrow(unsigned long request, void *arg, const char *name) {
        if (retrying(request, arg) == -1) throw DeviceError(errno, name);
    }

    // Enumerations end with EINVAL; anything else is a real failure.
    bool tryIoctl(unsigned long request, void *arg, const char *name) {
        if (retrying(request, arg) == 0) return true;
        if (errno == EINVAL || errno == ENOTTY) return false;
        throw DeviceError(errno, name);
    }

    std::vector<FrameSize> frameSizes(uint32_t fourcc) {
        std::vector<FrameSize> sizes;
        for (uint32_t index = 0;; ++index) {
            v4l2_frmsizeenum fs{};
            fs.index = index;
            fs.pixel_format = fourcc;
            if (!tryIoctl(VIDIOC_ENUM_FRAMESIZES, &fs, "VIDIOC_ENUM_FRAMESIZES")) break;
            if (fs.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
                sizes.push_back({fs.discrete.width, fs.discrete.height});
            } else { // stepwise or continuous: one entry, described by its bounds
                sizes.push_back({fs.stepwise.min_width, fs.stepwise.min_height});
                sizes.push_back({fs.stepwise.max_width, fs.stepwise.max_height});
                break;
            }
        }
        return sizes;
    }

    std::string path_;
    int fd_ = -1;
    std::map<uint32_t, Mapping> mapped_;
};

class LinuxSystem : public System {
public:
    std::vector<std::string> listDevices() override {
        namespace fs = std::filesystem;
        std::vector<std::pair<long, std::string>> found;
        std::error_code ec;
        for (fs::directory_iterator it("/dev", ec), end; !ec && it != end; it.increment(ec)) {
            const std::string name = it->path().filename().string();
            if (name.rfind("video", 0) != 0 || name.size() == 5) continue;
            const std::string digits = name.substr(5);
            if (digits.find_first_not_of("0123456789") != std::string::npos) continue;
            found.emplace_back(std::stol(digits), it->path().string());
        }
        std::sort(found.begin(), found.end());
        std::vector<std::string> paths;
        for (auto &f : found) paths.push_back(std::move(f.second));
        return paths;
    }

    std::unique_ptr<Device> open(const std::string &path) override { return std::make_unique<LinuxDevice>(path); }
};

} // namespace

System &deviceSystem() {
    static LinuxSystem system;
    return system;
}

} // namespace binocle::v4l2
