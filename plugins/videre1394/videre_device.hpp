// SPDX-License-Identifier: MIT
// videre1394: the thin device layer between the plugin's logic and libdc1394. The
// plugin links the libdc1394 implementation (videre_device_dc1394.cpp); tests link a
// fake.
//
// Each call mirrors one libdc1394 step and reports failures as a DeviceError whose kind
// says what the logic needs to know (no bus, camera gone, call failed); the wording a
// user reads is decided by the logic (videre_source.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace binocle::videre1394 {

class DeviceError : public std::runtime_error {
public:
    enum class Kind {
        NoBus,  // no IEEE-1394 stack or controller (dc1394_new failed)
        Gone,   // the camera went away (unplugged, bus reset, poll error)
        Failed  // a libdc1394 call failed; what() names it and libdc1394's reason
    };
    DeviceError(Kind kind, const std::string &message) : std::runtime_error(message), kind_(kind) {}
    Kind kind() const noexcept { return kind_; }

private:
    Kind kind_;
};

struct CameraInfo {
    uint64_t guid = 0;
    int unit = 0;
    std::string vendor, model;
};

// A video mode the camera offers (dc1394_video_get_supported_modes).
struct VideoMode {
    uint32_t id = 0;          // dc1394video_mode_t
    std::string name;         // "640x480_MONO16", "format7_0"
    uint32_t width = 0;       // pixels of the 1394 frame (format7: the largest image)
    uint32_t height = 0;
    std::string coding;       // "MONO16", "RAW16", "MONO8", "YUV422" ...
    uint32_t bitsPerPixel = 0;
    bool format7 = false;
    std::vector<double> framerates; // fps offered (empty for format7: set by packet size)
};

// A filled DMA buffer, from dequeue until it is enqueued again.
struct RawFrame {
    uint8_t *image = nullptr;  // the pixels, writable (libdc1394 allows it)
    uint32_t width = 0, height = 0;
    uint32_t stride = 0;       // bytes per line
    uint32_t bitsPerPixel = 0;
    uint64_t imageBytes = 0;   // bytes the buffer holds for the image
    uint64_t timestampUs = 0;  // when the frame reached the ring buffer (unix time)
    uint32_t framesBehind = 0; // frames still waiting in the ring
    bool corrupt = false;      // dc1394_capture_is_frame_corrupt
    void *handle = nullptr;    // the implementation's own (dc1394video_frame_t *)
};

// One opened camera. enqueue may come from another thread than dequeue (a lent frame is
// released by whoever holds it); the logic serialises every call but waitForFrame.
class Camera {
public:
    virtual ~Camera() = default; // stops transmission and capture, frees the camera
    virtual CameraInfo info() const = 0;
    virtual std::vector<VideoMode> modes() = 0;
    // dc1394_video_set_iso_speed, _set_mode, then _set_framerate (or format7's largest
    // image in the mode's coding with the largest packets).
    virtual void configure(const VideoMode &mode, double fps, uint32_t isoSpeedMbps) = 0;
    // The calibration text a Videre head keeps in its memory; "" when it has none.
    virtual std::string readStoredCalibration() = 0;
    virtual void setupCapture(uint32_t buffers) = 0; // dc1394_capture_setup: DMA ring
    virtual void stopCapture() = 0;                  // dc1394_capture_stop: ring freed
    virtual void startTransmission() = 0;            // dc1394_video_set_transmission ON
    virtual void stopTransmission() = 0;             // ... OFF
    // Waits at most timeoutMs (< 0: no limit) for a frame: poll on the capture's file
    // descriptor. False when none came in time; throws Gone when poll reports an error.
    virtual bool waitForFrame(int timeoutMs) = 0;
    // dc1394_capture_dequeue(POLL), never blocks: false when the ring holds no frame.
    virtual bool dequeue(RawFrame &out) = 0;
    virtual void enqueue(const RawFrame &frame) = 0; // dc1394_capture_enqueue
};

class Bus {
public:
    virtual ~Bus() = default;
    // dc1394_camera_enumerate, with each camera's vendor and model. Throws NoBus.
    virtual std::vector<CameraInfo> cameras() = 0;
    // What the system says about its IEEE-1394 controllers, for messages.
    virtual std::string describe() = 0;
    virtual std::unique_ptr<Camera> open(const CameraInfo &camera) = 0;
};

// The bus the plugin talks to: libdc1394 in the plugin, a fake in tests (chosen at link
// time).
Bus &bus();

} // namespace binocle::videre1394
