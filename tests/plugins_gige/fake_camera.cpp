// SPDX-License-Identifier: MIT
// Aravis's fake GigE Vision camera, serving images a test chooses over real GVCP/GVSP on a
// loopback address. Only for use inside a private network namespace (scripts/netns-test.sh).
#include "fake_camera.hpp"

#include <net/if.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace binocle::test {

FakeCamera::FakeCamera(std::string address, std::string serial, std::vector<cv::Mat> frames)
    : address_(std::move(address)), serial_(std::move(serial)), state_(std::make_shared<State>()) {
    state_->frames = std::move(frames);
    start();
}

FakeCamera::~FakeCamera() { kill(); }

void FakeCamera::start() {
    camera_ = arv_gv_fake_camera_new(address_.c_str(), serial_.c_str());
    if (!camera_ || !arv_gv_fake_camera_is_running(camera_)) {
        if (camera_) g_object_unref(camera_);
        camera_ = nullptr;
        throw std::runtime_error("fake GigE camera at " + address_ +
                                 " did not start: is the address on lo? (run the tests through scripts/netns-test.sh)");
    }
    ArvFakeCamera *fake = arv_gv_fake_camera_get_fake_camera(camera_);
    // Software triggers are looked at every 2 ms (Aravis's default: every 40 ms).
    arv_fake_camera_set_trigger_frequency(fake, 500.0);
    arv_fake_camera_set_fill_pattern(fake, &FakeCamera::fill, state_.get());
}

void FakeCamera::kill() {
    if (!camera_) return;
    g_object_unref(camera_); // stops its thread and closes its sockets
    camera_ = nullptr;
}

void FakeCamera::revive() {
    if (!camera_) start();
}

void FakeCamera::setLostPacketRatio(double ratio) {
    if (camera_) g_object_set(camera_, "gvsp-lost-ratio", ratio, nullptr);
}

ArvFakeCamera *FakeCamera::fake() const { return camera_ ? arv_gv_fake_camera_get_fake_camera(camera_) : nullptr; }

void FakeCamera::setFrames(std::vector<cv::Mat> frames) {
    std::lock_guard<std::mutex> lock(state_->mutex);
    state_->frames = std::move(frames);
}

int FakeCamera::imagesSent() const {
    std::lock_guard<std::mutex> lock(state_->mutex);
    return state_->sent;
}

// Runs in the fake camera's thread; the buffer is at least width * height * bpp bytes
// (Aravis checks before calling).
void FakeCamera::fill(ArvBuffer *buffer, void *data, guint32, guint32, ArvPixelFormat format) {
    auto *state = static_cast<State *>(data);
    std::lock_guard<std::mutex> lock(state->mutex);
    const int width = arv_buffer_get_image_width(buffer), height = arv_buffer_get_image_height(buffer);
    const size_t bpp = std::max<size_t>(1, ARV_PIXEL_FORMAT_BIT_PER_PIXEL(format) / 8);
    auto *out = static_cast<uint8_t *>(const_cast<void *>(arv_buffer_get_data(buffer, nullptr)));
    const size_t rowBytes = static_cast<size_t>(width) * bpp;
    if (state->frames.empty()) {
        for (int y = 0; y < height; ++y)
            for (size_t x = 0; x < rowBytes; ++x) out[y * rowBytes + x] = static_cast<uint8_t>(x + y + state->sent);
    } else {
        const cv::Mat &m = state->frames[static_cast<size_t>(state->sent) % state->frames.size()];
        const size_t copy = std::min(rowBytes, m.cols * m.elemSize());
        for (int y = 0; y < height; ++y) {
            uint8_t *row = out + y * rowBytes;
            std::memset(row, 0, rowBytes);
            if (y < m.rows) std::memcpy(row, m.ptr(y), copy);
        }
    }
    ++state->sent;
}

bool networkIsIsolated(std::string *interfaces) {
    struct if_nameindex *list = if_nameindex();
    if (!list) return false;
    bool onlyLoopback = true;
    std::string names;
    for (struct if_nameindex *i = list; i->if_index != 0 && i->if_name; ++i) {
        names += (names.empty() ? "" : ", ") + std::string(i->if_name);
        if (std::strcmp(i->if_name, "lo") != 0) onlyLoopback = false;
    }
    if_freenameindex(list);
    if (interfaces) *interfaces = names;
    return onlyLoopback;
}

} // namespace binocle::test
