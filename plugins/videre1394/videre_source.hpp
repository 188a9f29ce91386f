// SPDX-License-Identifier: MIT
// videre1394: the StereoSource the plugin exports: a Videre Design stereo head on
// IEEE 1394, both imagers in one frame, left and right bytes interleaved in each 16-bit
// pixel.
//
// Compiled into the plugin with the libdc1394 device layer and into the tests with a
// fake one (see videre_device.hpp); nothing here touches the bus directly.
#pragma once

#include "videre_device.hpp"

#include <binocle/plugin.hpp>

#include <memory>
#include <string>
#include <vector>

namespace binocle::videre1394 {

struct Settings {
    std::string guid;                 // hexadecimal; empty: the first Videre Design head
    std::string videoMode = "640x480_MONO16";
    double fps = 15;
    int decimation = 1;
    bool leftIsFirstByte = false;     // left_byte: first | second
    uint32_t isoSpeedMbps = 400;
    uint32_t bufferCount = 4;
    bool useStoredCalibration = true;
};

// Splits one interleaved 16-bit frame with libdc1394's stereo deinterlacing and writes
// the two 8-bit images back into the same buffer, decimated by `decimation`: the left
// image first, the right image right after it, each (width/d) x (height/d) packed.
// `scratch` is working memory. Byte order: libdc1394 puts the first byte of each pixel
// (in memory order) in the first image; leftIsFirstByte says whether that is the left.
void splitInterleaved(uint8_t *image, uint32_t width, uint32_t height, uint32_t stride, int decimation,
                      bool leftIsFirstByte, std::vector<uint8_t> &scratch);

// Why a frame of this geometry cannot be split in a buffer of imageBytes, or "" when it
// can: 16-bit pixels, a positive size, stride >= 2 x width, every row inside the buffer
// (stride x (height - 1) + 2 x width bytes) and a decimation 1..8 dividing both sides.
// splitInterleaved() throws std::invalid_argument with this text; the source checks
// each frame with it first.
std::string interleavedFrameProblem(uint32_t width, uint32_t height, uint32_t stride, uint32_t bitsPerPixel,
                                    uint64_t imageBytes, int decimation);

// "0x00b09d0100a1b2c3".
std::string guidText(uint64_t guid);

class Capture; // the opened camera and its lent buffers (videre_source.cpp)

class VidereSource : public sdk::StereoSource {
public:
    static std::vector<binocle_param_desc> parameters();
    // Finds and opens the head, selects the mode and reads its stored calibration;
    // the DMA ring is set up at start.
    VidereSource(const sdk::CheckedParams &params, sdk::Host &host);
    ~VidereSource() override;

    void start() override;
    void stop() override;
    std::unique_ptr<sdk::Frame> grab(int32_t timeout_ms) override;
    std::string calibration() override { return calibration_; }
    std::string statistics() override;
    static std::string enumerateDevices(sdk::Host &host);

private:
    CameraInfo choose(const std::vector<CameraInfo> &cameras) const;
    void selectMode();
    void readCalibration();

    // The steps of grab(), in order.
    void checkRingHasRoom() const;
    RawFrame nextWholeFrame(int32_t timeout_ms);
    bool dequeue(RawFrame &f);
    bool acceptDequeued(RawFrame &f);
    sdk::Error lostCamera(const DeviceError &e);
    void checkFrameGeometry(const RawFrame &f);
    std::unique_ptr<sdk::Frame> lend(const RawFrame &f);

    sdk::Host host_;
    Settings settings_;
    std::shared_ptr<Capture> capture_;
    VideoMode mode_;
    uint32_t outWidth_ = 0, outHeight_ = 0;
    std::string calibration_;     // FileStorage YAML, empty when none
    std::string calibrationNote_; // what became of the stored calibration
    std::vector<uint8_t> scratch_;
    bool started_ = false;
    uint64_t sequence_ = 0;
};

} // namespace binocle::videre1394
