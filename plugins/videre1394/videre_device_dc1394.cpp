// SPDX-License-Identifier: MIT
// videre1394: the device layer of the plugin, on libdc1394 (2.x, Linux juju stack).
#include "videre_device.hpp"

#include <dc1394/dc1394.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <poll.h>
#include <unistd.h>

namespace binocle::videre1394 {
namespace {

// Where a Videre head keeps its calibration text: quadlets in its command register
// space, most significant byte first, ended by 0 or 0xffffffff (the layout Videre's SVS
// uses; a head without calibration reads 0xffffffff at the start).
constexpr uint64_t kVidereLocalBase = 0xF0000;
constexpr uint64_t kVidereCalibrationOffset = 0x0800;
constexpr uint64_t kVidereCalibrationBytes = 0x1000;

std::string callFailed(const char *call, dc1394error_t e) { return std::string(call) + ": " + dc1394_error_get_string(e); }

void check(dc1394error_t e, const char *call) {
    if (e != DC1394_SUCCESS) throw DeviceError(DeviceError::Kind::Failed, callFailed(call, e));
}

const char *codingName(dc1394color_coding_t c) {
    switch (c) {
    case DC1394_COLOR_CODING_MONO8: return "MONO8";
    case DC1394_COLOR_CODING_YUV411: return "YUV411";
    case DC1394_COLOR_CODING_YUV422: return "YUV422";
    case DC1394_COLOR_CODING_YUV444: return "YUV444";
    case DC1394_COLOR_CODING_RGB8: return "RGB8";
    case DC1394_COLOR_CODING_MONO16: return "MONO16";
    case DC1394_COLOR_CODING_RGB16: return "RGB16";
    case DC1394_COLOR_CODING_MONO16S: return "MONO16S";
    case DC1394_COLOR_CODING_RGB16S: return "RGB16S";
    case DC1394_COLOR_CODING_RAW8: return "RAW8";
    case DC1394_COLOR_CODING_RAW16: return "RAW16";
    }
    return "?";
}

bool codingFromName(const std::string &name, dc1394color_coding_t &out) {
    for (int c = DC1394_COLOR_CODING_MIN; c <= DC1394_COLOR_CODING_MAX; ++c)
        if (name == codingName(static_cast<dc1394color_coding_t>(c))) {
            out = static_cast<dc1394color_coding_t>(c);
            return true;
        }
    return false;
}

std::string guidText(uint64_t guid) {
    char b[32];
    std::snprintf(b, sizeof b, "0x%016llx", static_cast<unsigned long long>(guid));
    return b;
}

using Context = std::shared_ptr<dc1394_t>;

Context newContext() {
    dc1394_t *d = dc1394_new();
    if (!d) throw DeviceError(DeviceError::Kind::NoBus, "no IEEE-1394 bus found (dc1394_new failed)");
    return Context(d, dc1394_free);
}

class Dc1394Camera : public Camera {
public:
    Dc1394Camera(Context context, dc1394camera_t *camera, CameraInfo info)
        : context_(std::move(context)), camera_(camera), info_(std::move(info)) {}

    ~Dc1394Camera() override {
        if (transmitting_) dc1394_video_set_transmission(camera_, DC1394_OFF);
        if (capturing_) dc1394_capture_stop(camera_);
        dc1394_camera_free(camera_);
    }

    Dc1394Camera(const Dc1394Camera &) = delete;
    Dc1394Camera &operator=(const Dc1394Camera &) = delete;

    CameraInfo info() const override { return info_; }

    std::vector<VideoMode> modes() override {
        dc1394video_modes_t list{};
        check(dc1394_video_get_supported_modes(camera_, &list), "dc1394_video_get_supported_modes");
        std::vector<VideoMode> out;
        for (uint32_t i = 0; i < list.num; ++i) {
            const dc1394video_mode_t id = list.modes[i];
            if (id == DC1394_VIDEO_MODE_EXIF) continue;
            VideoMode m;
            m.id = id;
            dc1394color_coding_t coding = DC1394_COLOR_CODING_MONO8;
            if (dc1394_is_video_mode_scalable(id)) {
                m.format7 = true;
                m.name = "format7_" + std::to_string(id - DC1394_VIDEO_MODE_FORMAT7_0);
                check(dc1394_format7_get_max_image_size(camera_, id, &m.width, &m.height),
                      "dc1394_format7_get_max_image_size");
                // A stereo head's format7 mode offers its 16-bit coding; take it if present.
                dc1394color_codings_t codings{};
                check(dc1394_format7_get_color_codings(camera_, id, &codings), "dc1394_format7_get_color_codings");
                if (codings.num > 0) coding = codings.codings[0];
                for (uint32_t c = 0; c < codings.num; ++c)
                    if (codings.codings[c] == DC1394_COLOR_CODING_MONO16 || codings.codings[c] == DC1394_COLOR_CODING_RAW16)
                        coding = codings.codings[c];
            } else {
                check(dc1394_get_image_size_from_video_mode(camera_, id, &m.width, &m.height),
                      "dc1394_get_image_size_from_video_mode");
                check(dc1394_get_color_coding_from_video_mode(camera_, id, &coding),
                      "dc1394_get_color_coding_from_video_mode");
                m.name = std::to_string(m.width) + "x" + std::to_string(m.height) + "_" + codingName(coding);
                dc1394framerates_t rates{};
                check(dc1394_video_get_supported_framerates(camera_, id, &rates), "dc1394_video_get_supported_framerates");
                for (uint32_t r = 0; r < rates.num; ++r) {
                    float fps = 0;
                    if (dc1394_framerate_as_float(rates.framerates[r], &fps) == DC1394_SUCCESS) m.framerates.push_back(fps);
                }
            }
            m.coding = codingName(coding);
            dc1394_get_color_coding_bit_size(coding, &m.bitsPerPixel);
            out.push_back(std::move(m));
        }
        return out;
    }

    void configure(const VideoMode &mode, double fps, uint32_t isoSpeedMbps) override {
        dc1394speed_t speed = DC1394_ISO_SPEED_400;
        switch (isoSpeedMbps) {
        case 100: speed = DC1394_ISO_SPEED_100; break;
        case 200: speed = DC1394_ISO_SPEED_200; break;
        case 400: speed = DC1394_ISO_SPEED_400; break;
        case 800: speed = DC1394_ISO_SPEED_800; break;
        default:
            throw DeviceError(DeviceError::Kind::Failed, "iso speed " + std::to_string(isoSpeedMbps) +
                                                             " Mbit/s: expected 100, 200, 400 or 800");
        }
        if (speed == DC1394_ISO_SPEED_800)
            check(dc1394_video_set_operation_mode(camera_, DC1394_OPERATION_MODE_1394B), "dc1394_video_set_operation_mode");
        check(dc1394_video_set_iso_speed(camera_, speed), "dc1394_video_set_iso_speed");
        const auto id = static_cast<dc1394video_mode_t>(mode.id);
        check(dc1394_video_set_mode(camera_, id), "dc1394_video_set_mode");
        if (mode.format7) {
            dc1394color_coding_t coding;
            if (!codingFromName(mode.coding, coding))
                throw DeviceError(DeviceError::Kind::Failed, "format7: unknown color coding " + mode.coding);
            check(dc1394_format7_set_roi(camera_, id, coding, DC1394_USE_MAX_AVAIL, 0, 0, static_cast<int32_t>(mode.width),
                                         static_cast<int32_t>(mode.height)),
                  "dc1394_format7_set_roi");
            return;
        }
        for (int r = DC1394_FRAMERATE_MIN; r <= DC1394_FRAMERATE_MAX; ++r) {
            float f = 0;
            const auto rate = static_cast<dc1394framerate_t>(r);
            if (dc1394_framerate_as_float(rate, &f) == DC1394_SUCCESS && std::abs(f - fps) < 1e-3) {
                check(dc1394_video_set_framerate(camera_, rate), "dc1394_video_set_framerate");
                return;
            }
        }
        throw DeviceError(DeviceError::Kind::Failed, "no IIDC frame rate of " + std::to_string(fps) + " fps");
    }

    std::string readStoredCalibration() override {
        std::string text;
        for (uint64_t pos = 0; pos < kVidereCalibrationBytes; pos += 4) {
            uint32_t quad = 0;
            check(dc1394_get_control_register(camera_, kVidereLocalBase + kVidereCalibrationOffset + pos, &quad),
                  "dc1394_get_control_register (stored calibration)");
            if (quad == 0 || quad == 0xffffffffu) break;
            for (int shift = 24; shift >= 0; shift -= 8) {
                const char c = static_cast<char>((quad >> shift) & 0xff);
                if (c == '\0') return text;
                text += c;
            }
        }
        return text;
    }

    void setupCapture(uint32_t buffers) override {
        check(dc1394_capture_setup(camera_, buffers, DC1394_CAPTURE_FLAGS_DEFAULT), "dc1394_capture_setup");
        capturing_ = true;
    }

    void stopCapture() override {
        if (!capturing_) return;
        capturing_ = false;
        check(dc1394_capture_stop(camera_), "dc1394_capture_stop");
    }

    void startTransmission() override {
        check(dc1394_video_set_transmission(camera_, DC1394_ON), "dc1394_video_set_transmission");
        transmitting_ = true;
    }

    void stopTransmission() override {
        if (!transmitting_) return;
        transmitting_ = false;
        check(dc1394_video_set_transmission(camera_, DC1394_OFF), "dc1394_video_set_transmission");
    }

    bool waitForFrame(int timeoutMs) override {
        const int fd = dc1394_capture_get_fileno(camera_);
        if (fd < 0) throw DeviceError(DeviceError::Kind::Failed, "dc1394_capture_get_fileno: capture is not set up");
        using Clock = std::chrono::steady_clock;
        const auto deadline = Clock::now() + std::chrono::milliseconds(std::max(timeoutMs, 0));
        for (;;) {
            pollfd p{fd, POLLIN, 0};
            int wait = timeoutMs;
            if (timeoutMs >= 0)
                wait = static_cast<int>(std::max<int64_t>(
                    0, std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count()));
            const int rc = poll(&p, 1, wait);
            if (rc < 0) {
                if (errno == EINTR) continue;
                throw DeviceError(DeviceError::Kind::Gone, std::string("poll: ") + std::strerror(errno));
            }
            if (rc == 0) return false;
            if (p.revents & (POLLERR | POLLHUP | POLLNVAL))
                throw DeviceError(DeviceError::Kind::Gone, "poll on the capture reported an error");
            return true;
        }
    }

    bool dequeue(RawFrame &out) override {
        dc1394video_frame_t *f = nullptr;
        const dc1394error_t e = dc1394_capture_dequeue(camera_, DC1394_CAPTURE_POLICY_POLL, &f);
        if (e != DC1394_SUCCESS) throw DeviceError(DeviceError::Kind::Gone, callFailed("dc1394_capture_dequeue", e));
        if (!f) return false;
        out.image = f->image;
        out.width = f->size[0];
        out.height = f->size[1];
        out.stride = f->stride;
        out.bitsPerPixel = 0;
        dc1394_get_color_coding_bit_size(f->color_coding, &out.bitsPerPixel);
        out.imageBytes = f->image_bytes;
        out.timestampUs = f->timestamp;
        out.framesBehind = f->frames_behind;
        out.corrupt = dc1394_capture_is_frame_corrupt(camera_, f) == DC1394_TRUE;
        out.handle = f;
        return true;
    }

    void enqueue(const RawFrame &frame) override {
        check(dc1394_capture_enqueue(camera_, static_cast<dc1394video_frame_t *>(frame.handle)), "dc1394_capture_enqueue");
    }

private:
    Context context_; // outlives the camera
    dc1394camera_t *camera_;
    CameraInfo info_;
    bool capturing_ = false, transmitting_ = false;
};

class Dc1394Bus : public Bus {
public:
    std::vector<CameraInfo> cameras() override {
        Context context = newContext();
        dc1394camera_list_t *list = nullptr;
        const dc1394error_t e = dc1394_camera_enumerate(context.get(), &list);
        if (e != DC1394_SUCCESS)
            throw DeviceError(DeviceError::Kind::NoBus,
                              "no IEEE-1394 bus found (" + callFailed("dc1394_camera_enumerate", e) + ")");
        std::vector<CameraInfo> out;
        for (uint32_t i = 0; list && i < list->num; ++i) {
            CameraInfo info;
            info.guid = list->ids[i].guid;
            info.unit = list->ids[i].unit;
            if (dc1394camera_t *c = dc1394_camera_new_unit(context.get(), info.guid, info.unit)) {
                info.vendor = c->vendor ? c->vendor : "";
                info.model = c->model ? c->model : "";
                dc1394_camera_free(c);
            } else {
                info.model = "(cannot be opened: in use by another program?)";
            }
            out.push_back(std::move(info));
        }
        if (list) dc1394_camera_free_list(list);
        return out;
    }

    std::string describe() override {
        namespace fs = std::filesystem;
        int nodes = 0, usable = 0;
        std::error_code ec;
        for (fs::directory_iterator it("/dev", ec), end; !ec && it != end; it.increment(ec)) {
            const std::string name = it->path().filename().string();
            if (name.rfind("fw", 0) != 0 || name.size() < 3 ||
                name.find_first_not_of("0123456789", 2) != std::string::npos)
                continue;
            ++nodes;
            if (::access(it->path().c_str(), R_OK | W_OK) == 0) ++usable;
        }
        if (nodes == 0)
            return "no /dev/fw* node: no IEEE-1394 controller, or its driver (firewire-ohci) is not loaded";
        if (usable == 0)
            return std::to_string(nodes) + " /dev/fw* nodes, none readable and writable by this user";
        return std::to_string(nodes) + " /dev/fw* nodes, " + std::to_string(usable) + " usable; no camera answered";
    }

    std::unique_ptr<Camera> open(const CameraInfo &camera) override {
        Context context = newContext();
        dc1394camera_t *c = dc1394_camera_new_unit(context.get(), camera.guid, camera.unit);
        if (!c)
            throw DeviceError(DeviceError::Kind::Failed, "dc1394_camera_new_unit failed for GUID " + guidText(camera.guid) +
                                                             ": the camera went away or another program holds it");
        return std::make_unique<Dc1394Camera>(std::move(context), c, camera);
    }
};

} // namespace

Bus &bus() {
    static Dc1394Bus b;
    return b;
}

} // namespace binocle::videre1394
