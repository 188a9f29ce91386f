// SPDX-License-Identifier: MIT
// Aravis's fake GigE Vision camera, serving images a test chooses over real GVCP/GVSP on a
// loopback address. Only for use inside a private network namespace (scripts/netns-test.sh).
#pragma once

#include <arv.h>
#include <opencv2/core.hpp>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace binocle::test {

class FakeCamera {
public:
    // A camera at `address` (a 127.0.0.x address present on `lo`) with serial number
    // `serial` (device id "Aravis-Fake-<serial>"). Its k-th image is frames[k % n]: the bytes
    // of each Mat, row by row, in the pixel format the camera is set to (CV_8UC1 for Mono8
    // and Bayer, CV_8UC3 holding R,G,B for RGB8). No frames: Aravis's own diagonal ramp.
    FakeCamera(std::string address, std::string serial, std::vector<cv::Mat> frames = {});
    ~FakeCamera();
    FakeCamera(const FakeCamera &) = delete;
    FakeCamera &operator=(const FakeCamera &) = delete;

    void setFrames(std::vector<cv::Mat> frames);
    // The camera vanishes (cable pulled, power lost): nothing answers at its address.
    void kill();
    // The same camera answers again, freshly powered (no controller, default settings).
    void revive();
    // Share of GVSP packets the camera drops on purpose (0..1), as a bad link would.
    void setLostPacketRatio(double ratio);
    bool alive() const { return camera_ != nullptr; }
    ArvFakeCamera *fake() const;
    int imagesSent() const;

    const std::string &address() const { return address_; }
    std::string deviceId() const { return "Aravis-Fake-" + serial_; }

private:
    struct State {
        std::mutex mutex;
        std::vector<cv::Mat> frames;
        int sent = 0;
    };
    static void fill(ArvBuffer *buffer, void *data, guint32 exposure_us, guint32 gain, ArvPixelFormat format);
    void start();

    std::string address_, serial_;
    std::shared_ptr<State> state_;
    ArvGvFakeCamera *camera_ = nullptr;
};

// Aravis's fake camera as a process of its own (`arv-fake-gv-camera-0.8 -i ADDRESS -s
// SERIAL`), as a real camera is: its packets cross the kernel's loopback between two
// processes. kill() ends the process (a camera unplugged), start() starts it again.
class ExternalFakeCamera {
public:
    ExternalFakeCamera(std::string address, std::string serial);
    ~ExternalFakeCamera();
    ExternalFakeCamera(const ExternalFakeCamera &) = delete;
    ExternalFakeCamera &operator=(const ExternalFakeCamera &) = delete;

    // False when the program is not installed or the camera did not answer within 5 s;
    // `why` says which.
    bool start(std::string *why = nullptr);
    void kill();
    bool alive() const { return pid_ > 0; }
    const std::string &address() const { return address_; }

    static const char *program() { return "arv-fake-gv-camera-0.8"; }

private:
    std::string address_, serial_;
    int pid_ = -1;
};

// True when this process sees no network interface but `lo`: the only place where the
// tests may run Aravis (its discovery broadcasts on every interface).
bool networkIsIsolated(std::string *interfaces = nullptr);

} // namespace binocle::test
