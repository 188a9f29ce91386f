// SPDX-License-Identifier: MIT
// Aravis's fake GigE Vision camera, serving images a test chooses over real GVCP/GVSP on a
// loopback address. Only for use inside a private network namespace (scripts/netns-test.sh).
#include "fake_camera.hpp"

#include <fcntl.h>
#include <net/if.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <thread>
#include <vector>

extern char **environ;

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

namespace {

// True when a UDP socket is bound to ADDRESS:3956 (GVCP) in this namespace: the camera answers.
bool gvcpPortOpen(const std::string &address) {
    unsigned a = 0, b = 0, c = 0, d = 0;
    if (std::sscanf(address.c_str(), "%u.%u.%u.%u", &a, &b, &c, &d) != 4) return false;
    char wanted[32];
    std::snprintf(wanted, sizeof wanted, "%02X%02X%02X%02X:0F74", d, c, b, a); // little-endian, port 3956
    std::ifstream udp("/proc/net/udp");
    for (std::string line; std::getline(udp, line);)
        if (line.find(wanted) != std::string::npos) return true;
    return false;
}

} // namespace

ExternalFakeCamera::ExternalFakeCamera(std::string address, std::string serial)
    : address_(std::move(address)), serial_(std::move(serial)) {}

ExternalFakeCamera::~ExternalFakeCamera() { kill(); }

bool ExternalFakeCamera::start(std::string *why) {
    if (pid_ > 0) return true;
    const std::string program = ExternalFakeCamera::program();
    std::vector<std::string> args = {program, "-i", address_, "-s", serial_};
    std::vector<char *> argv;
    for (auto &a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    pid_t pid = -1;
    const int rc = posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
        if (why) *why = program + " cannot be started: " + std::strerror(rc) + " (Debian: aravis-tools)";
        return false;
    }
    pid_ = pid;
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (!gvcpPortOpen(address_)) {
        int status = 0;
        if (::waitpid(pid_, &status, WNOHANG) == pid_) {
            pid_ = -1;
            if (why) *why = program + " -i " + address_ + " exited at once (status " + std::to_string(status) + ")";
            return false;
        }
        if (std::chrono::steady_clock::now() > until) {
            kill();
            if (why) *why = program + " -i " + address_ + " did not open its GVCP port within 5 s";
            return false;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return true;
}

void ExternalFakeCamera::kill() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL); // as a camera that loses power: no goodbye
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
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
