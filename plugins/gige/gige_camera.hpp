// SPDX-License-Identifier: MIT
// One GigE Vision camera through Aravis: opened by device id or IP address, configured
// from the rig's settings, streaming into buffers that the source lends without copying.
#pragma once

#include "pixel_formats.hpp"

#include <arv.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace binocle::gige {

using Clock = std::chrono::steady_clock;

// Wakes the source's grab when any stream has finished a buffer, a camera is lost or a
// lost camera is back. Waiters pass the event count they have seen, so no wake-up is lost.
class Notifier {
public:
    void notify();
    uint64_t events();
    // Returns when an event newer than `seen` happened, or at `until`.
    void wait(uint64_t seen, Clock::time_point until);

private:
    std::mutex mutex_;
    std::condition_variable cv_;
    uint64_t events_ = 0;
};

// Where a lent buffer goes back to: its stream while the camera is open; once the camera
// is closed (or lost) the buffer is simply freed. Safe from any thread.
class BufferHome {
public:
    explicit BufferHome(ArvStream *stream); // takes a reference
    ~BufferHome();
    void lend(ArvBuffer *buffer);
    void giveBack(ArvBuffer *buffer);
    void push(ArvBuffer *buffer); // a buffer that was never lent
    int lent() const { return lent_.load(); }
    // Detaches from the stream; the caller receives the stream's reference.
    ArvStream *retire();

private:
    std::mutex mutex_;
    ArvStream *stream_;
    std::atomic<int> lent_{0};
};

// What starts an image: the camera's own clock, a command from the host, or a signal on
// an input line.
enum class Trigger { FreeRun, Software, Hardware };

// The `trigger` setting's names: free_run | software | hardware. nullopt for any other.
std::optional<Trigger> triggerNamed(const std::string &name);

struct CameraSettings {
    std::string id;   // device id or IP address, as written in the YAML
    std::string key;  // the YAML key it came from ("camera_left")
    std::string role; // "left", "right" or "left+right"
    const PixelFormat *format = nullptr;
    std::optional<int64_t> width, height; // unset: keep the camera's
    std::optional<double> exposure_us, gain_db, frame_rate_hz;
    Trigger trigger = Trigger::FreeRun;
    std::string trigger_line = "Line0";
    std::optional<int64_t> packet_size; // unset: the largest the path carries
    std::optional<int64_t> packet_delay_ns;
    int64_t socket_buffer_bytes = 0; // 0: room for `buffers` images
    bool packet_resend = true;
    bool packet_socket = false; // Aravis's AF_PACKET receiver (see README: reopening)
    int buffers = 8;
};

struct StreamCounters {
    uint64_t completed = 0, failed = 0, underruns = 0, missing_packets = 0, resent_packets = 0;
    StreamCounters &operator+=(const StreamCounters &o);
};

class Camera {
public:
    // Opens and configures the camera; throws sdk::Error naming the camera and the value it
    // refused. `listOnFailure`: when no camera answers, name those that do (costs a discovery).
    Camera(const CameraSettings &settings, std::shared_ptr<Notifier> notifier, bool listOnFailure = true);
    // Talks to the camera (AcquisitionStop) only while it answers. Closing a camera that is
    // gone waits for Aravis's control-channel timeouts (seconds): do it away from grab.
    ~Camera();
    Camera(const Camera &) = delete;
    Camera &operator=(const Camera &) = delete;

    // "127.0.0.2 (left)", "Aravis-Fake-GV01 at 127.0.0.2 (left)".
    const std::string &label() const { return label_; }
    const std::string &address() const { return address_; }
    const CameraSettings &settings() const { return settings_; }
    int width() const { return width_; }
    int height() const { return height_; }
    const PixelFormat &format() const { return *settings_.format; }

    void start(); // queues the buffers (first time) and sends AcquisitionStart
    void stop();
    bool acquiring() const { return acquiring_; }
    ArvBuffer *tryPop();
    const std::shared_ptr<BufferHome> &home() const { return home_; }
    void softwareTrigger(); // throws sdk::Error(BINOCLE_ERR_DEVICE) when the camera does not answer

    // Why the camera is considered gone (control lost, trigger unanswered); empty while fine.
    std::string lostReason() const;
    void markLost(const std::string &why);
    StreamCounters counters() const;
    // Receive buffer asked for each stream socket, and what the kernel grants at most
    // (net.core.rmem_max; 0 when unknown). Packet size in use (0 when not GigE Vision).
    int64_t socketBufferBytes() const { return socketBufferBytes_; }
    int64_t socketBufferLimitBytes() const { return socketBufferLimitBytes_; }
    int64_t packetSize() const { return packetSize_; }

    // Every device Aravis sees, as "id (address)" list; "none" when empty. Runs a discovery.
    static std::string listDevices();

private:
    struct LostState {
        std::mutex mutex;
        std::string reason;
        std::shared_ptr<Notifier> notifier;
    };
    void configure();
    void identify();
    void configurePixelFormat();
    void configureImageSize();
    void configureExposureGainRate();
    void configureTrigger();
    void openStream();
    void configureTransport();    // packet size and delay, on the camera
    void configureStreamSocket(); // receive buffer and resend policy, on the stream
    [[noreturn]] void fail(int32_t code, const std::string &what) const;
    static void onStreamEvent(void *data, ArvStreamCallbackType type, ArvBuffer *buffer);
    static void onControlLost(ArvGvDevice *device, void *data);

    CameraSettings settings_;
    std::shared_ptr<Notifier> notifier_;
    std::shared_ptr<LostState> lost_;
    ArvCamera *camera_ = nullptr;
    ArvStream *stream_ = nullptr; // reference owned by home_ once created
    std::shared_ptr<BufferHome> home_;
    unsigned long controlLostHandler_ = 0;
    std::string address_, label_;
    int width_ = 0, height_ = 0;
    size_t payload_ = 0;
    int64_t socketBufferBytes_ = 0, socketBufferLimitBytes_ = 0, packetSize_ = 0;
    bool buffersQueued_ = false;
    std::atomic<bool> acquiring_{false};
};

// Sends one camera's software triggers from a thread of its own: a camera that is gone
// takes seconds to fail, and must delay neither grab nor the other camera's trigger.
class TriggerWorker {
public:
    explicit TriggerWorker(std::shared_ptr<Camera> camera);
    ~TriggerWorker(); // waits for a trigger in flight (bounded by Aravis's timeouts)
    void request();

private:
    void loop();
    // Sets `flag` (stop_ or pending_) under the lock and wakes the loop.
    void wake(bool &flag);
    std::shared_ptr<Camera> camera_;
    std::mutex mutex_;
    std::condition_variable cv_;
    bool stop_ = false, pending_ = false;
    std::thread thread_;
};

} // namespace binocle::gige
