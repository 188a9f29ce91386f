// SPDX-License-Identifier: MIT
// v4l2: the thin device layer between the plugin's logic and the kernel. The plugin
// links the libv4l2 implementation (v4l2_device_linux.cpp); tests link a fake.
//
// Each call mirrors one V4L2 request and fails the way the kernel does: a DeviceError
// carrying the errno (ENOENT, EBUSY, ENODEV ...) and the request's name. What the
// errors mean to a user is decided by the logic (v4l2_source.cpp), not here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace binocle::v4l2 {

// A failed system call: errno and the call ("open", "VIDIOC_S_FMT", "mmap" ...).
class DeviceError : public std::runtime_error {
public:
    DeviceError(int err, const std::string &call);
    int err() const noexcept { return err_; }
    const std::string &call() const noexcept { return call_; }

private:
    int err_;
    std::string call_;
};

// VIDIOC_QUERYCAP; `capabilities` holds device_caps when the driver sets them.
struct Capability {
    std::string driver, card, busInfo;
    uint32_t capabilities = 0; // V4L2_CAP_*
};

struct FrameSize {
    uint32_t width = 0, height = 0;
};

// VIDIOC_ENUM_FMT with its VIDIOC_ENUM_FRAMESIZES. A stepwise or continuous range is
// listed by its smallest and largest size.
struct FormatDesc {
    uint32_t fourcc = 0;
    std::string description;
    bool emulated = false; // converted in software by libv4l2
    std::vector<FrameSize> sizes;
};

// The single-planar pixel format of VIDIOC_S_FMT.
struct PixFormat {
    uint32_t fourcc = 0;
    uint32_t width = 0, height = 0;
    uint32_t bytesPerLine = 0; // 0 for compressed formats
    uint32_t sizeImage = 0;    // bytes a buffer must hold
};

// A buffer mapped into our address space (VIDIOC_QUERYBUF + mmap).
struct Mapping {
    uint8_t *data = nullptr;
    size_t length = 0;
};

// A filled buffer taken from the driver (VIDIOC_DQBUF).
struct Dequeued {
    uint32_t index = 0;
    uint32_t bytesUsed = 0;
    uint32_t flags = 0;    // V4L2_BUF_FLAG_*
    uint32_t sequence = 0; // the driver's frame counter (gaps = dropped frames)
    int64_t timestampNs = 0;
};

enum class Wait { Ready, Timeout, Error };

// One opened /dev/videoN. Calls may come from several threads (a lent buffer is
// re-queued from whichever thread releases the frame); the logic serialises them.
class Device {
public:
    virtual ~Device() = default; // unmaps what is still mapped, closes
    virtual const std::string &path() const = 0;
    virtual Capability queryCapability() = 0;             // VIDIOC_QUERYCAP
    virtual std::vector<FormatDesc> formats() = 0;        // VIDIOC_ENUM_FMT + ENUM_FRAMESIZES
    virtual PixFormat setFormat(const PixFormat &wanted) = 0; // VIDIOC_S_FMT: what the driver chose
    // VIDIOC_S_PARM: the frame rate granted, or 0 when the driver cannot set one.
    virtual double setFrameRate(double fps) = 0;
    virtual uint32_t requestBuffers(uint32_t count) = 0;  // VIDIOC_REQBUFS (MMAP): count granted
    virtual Mapping mapBuffer(uint32_t index) = 0;        // VIDIOC_QUERYBUF + mmap
    virtual void unmapBuffer(uint32_t index) = 0;         // munmap
    virtual void queueBuffer(uint32_t index) = 0;         // VIDIOC_QBUF
    virtual bool dequeueBuffer(Dequeued &out) = 0;        // VIDIOC_DQBUF, non-blocking: false on EAGAIN
    // poll(POLLIN) for at most timeoutMs (< 0: no limit). Error: POLLERR/POLLHUP, e.g.
    // not streaming or the device went away (the next dequeue tells which).
    virtual Wait waitForFrame(int timeoutMs) = 0;
    virtual void streamOn() = 0;                          // VIDIOC_STREAMON
    virtual void streamOff() = 0;                         // VIDIOC_STREAMOFF: every buffer back to us
};

class System {
public:
    virtual ~System() = default;
    // Paths of /dev/video* nodes, in numeric order.
    virtual std::vector<std::string> listDevices() = 0;
    // open(O_RDWR | O_NONBLOCK); throws DeviceError (ENOENT when there is no such node).
    virtual std::unique_ptr<Device> open(const std::string &path) = 0;
};

// The system the plugin talks to: libv4l2 in the plugin, a fake in tests (chosen at
// link time).
System &deviceSystem();

// "YUYV", "MJPG": the four characters of a V4L2 fourcc.
std::string fourccText(uint32_t fourcc);

} // namespace binocle::v4l2
