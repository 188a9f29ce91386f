// SPDX-License-Identifier: MIT
// v4l2: one opened device and its buffers (Stream), and the errors a user reads when the
// kernel refuses a call (throwFor: errno -> what happened, on which device, doing what).
#pragma once

#include "v4l2_device.hpp"

#include <binocle/plugin.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace binocle::v4l2 {

// Turns what the kernel said into what a user reads. `doing` says what was under way.
[[noreturn]] void throwFor(const std::string &path, const DeviceError &e, const std::string &doing);

// An opened device with its buffers. Shared by the source and by every frame lent from
// its buffers, so that the mappings outlive whichever goes last. Device calls and the
// book-keeping below happen under `mutex`, except waiting (poll), so that a frame can be
// released from another thread while grab waits.
class Stream {
public:
    Stream(std::unique_ptr<Device> device, std::string role)
        : path(device->path()), role(std::move(role)), device_(std::move(device)) {}

    ~Stream() {
        std::lock_guard<std::mutex> lock(mutex);
        try {
            if (streaming) device_->streamOff();
        } catch (...) {
        }
        for (uint32_t i = 0; i < buffers.size(); ++i) {
            try {
                device_->unmapBuffer(i);
            } catch (...) {
            }
        }
        try {
            if (!buffers.empty()) device_->requestBuffers(0);
        } catch (...) {
        }
    }

    Stream(const Stream &) = delete;
    Stream &operator=(const Stream &) = delete;

    Device &device() { return *device_; }

    // A lent buffer comes back (a frame's onRelease, any thread). Never throws.
    void giveBack(uint32_t index) noexcept {
        std::lock_guard<std::mutex> lock(mutex);
        if (index >= lent.size() || !lent[index]) return;
        lent[index] = 0;
        if (!streaming || !gone.empty()) return; // queued again at the next start, or never
        try {
            device_->queueBuffer(index);
            ++requeued;
        } catch (const DeviceError &e) {
            try {
                failLocked(e, "giving a released buffer back to the driver"); // remembers a vanished device
            } catch (...) {
            }
        } catch (...) {
        }
    }

    // Back to the driver after use (grab's thread). Caller holds no lock.
    void requeue(uint32_t index) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!streaming) return;
        try {
            device_->queueBuffer(index);
            ++requeued;
        } catch (const DeviceError &e) {
            failLocked(e, "giving buffer " + std::to_string(index) + " back to the driver");
        }
    }

    uint32_t lentCount() const {
        return static_cast<uint32_t>(std::count(lent.begin(), lent.end(), static_cast<char>(1)));
    }

    // Remembers a vanished device (so that every later call says so) and throws.
    [[noreturn]] void failLocked(const DeviceError &e, const std::string &doing) {
        try {
            throwFor(path, e, doing + " (" + role + ", after " + std::to_string(dequeued) + " frames)");
        } catch (const sdk::Error &err) {
            if (err.code() == BINOCLE_ERR_DEVICE && (e.err() == ENODEV || e.err() == ENXIO)) gone = err.what();
            throw;
        }
    }

    std::mutex mutex;
    std::string path, role;
    Capability capability;
    PixFormat format;
    double fpsGranted = 0;
    std::vector<Mapping> buffers;
    std::vector<char> lent; // by buffer index: 1 while the host holds it
    bool streaming = false;
    std::string gone; // the message, once the device went away

    // Statistics.
    uint64_t dequeued = 0, corrupt = 0, unpaired = 0, requeued = 0, droppedByDriver = 0;
    int64_t lastSequence = -1;

private:
    std::unique_ptr<Device> device_;
};

} // namespace binocle::v4l2
