// SPDX-License-Identifier: MIT
// videre1394: the logic of the plugin: settings, choice of the head and its video mode,
// the stored calibration, capture from the DMA ring, splitting of the interleaved pair,
// decimation, lending of the DMA buffers and the errors a user reads.
//
// Read top to bottom: settings, splitting, the capture (shared with lent frames), the
// source.
#include "videre_source.hpp"

#include "svs_calibration.hpp"

#include <binocle/settings.hpp>
#include <dc1394/conversions.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace binocle::videre1394 {

using sdk::Error;

// ---- Settings ------------------------------------------------------------------------------

std::vector<binocle_param_desc> VidereSource::parameters() {
    using sdk::Param;
    return {
        Param::string("guid", "")
            .help("hexadecimal GUID of the head, e.g. 0x00b09d0100a1b2c3; empty: the first Videre Design head"),
        Param::string("video_mode", "640x480_MONO16")
            .help("IIDC mode carrying the interleaved pair: WxH_MONO16, WxH_RAW16 or format7_N (largest image)"),
        Param::real("fps", "15").min(0).max(240).unit("Hz")
            .help("IIDC frame rate of the mode (1.875, 3.75, 7.5, 15, 30, 60 ...); format7 modes ignore it"),
        Param::integer("decimation", "1").min(1).max(8)
            .help("images are averaged over d x d blocks: 4 turns 1280x960 into 320x240"),
        Param::choice("left_byte", "second", "first|second")
            .help("which byte of each 16-bit pixel, in memory order, holds the left image (Videre: the second)"),
        Param::choice("iso_speed_mbps", "400", "100|200|400|800").unit("Mbit/s").help("IEEE-1394 isochronous speed"),
        Param::integer("buffer_count", "4").min(2).max(64).help("DMA buffers in libdc1394's capture ring"),
        Param::boolean("use_stored_calibration", true)
            .help("publish the calibration stored in the head (SVS parameters), scaled to the delivered images"),
    };
}

namespace {

std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

std::string describe(const CameraInfo &c) {
    std::string what = c.vendor;
    if (!c.model.empty()) what += (what.empty() ? "" : " ") + c.model;
    return guidText(c.guid) + (what.empty() ? "" : " " + what);
}

bool isVidere(const CameraInfo &c) { return lower(c.vendor).find("videre") != std::string::npos; }

// The table above is the one home of each setting's default, bounds and choices: the
// SDK checked `c` against it before the constructor (a setting the host did not pass is
// its default).
Settings readSettings(const sdk::CheckedParams &c) {
    Settings s;
    s.guid = c.string("guid");
    s.videoMode = c.string("video_mode");
    s.fps = c.real("fps");
    s.decimation = static_cast<int>(c.integer("decimation"));
    s.leftIsFirstByte = c.string("left_byte") == "first";
    s.isoSpeedMbps = static_cast<uint32_t>(std::stoul(c.string("iso_speed_mbps"))); // one of its choices
    s.bufferCount = static_cast<uint32_t>(c.integer("buffer_count"));
    s.useStoredCalibration = c.boolean("use_stored_calibration");
    if (s.videoMode.empty()) c.refuse("video_mode", "''", "a mode such as 640x480_MONO16 or format7_0");
    return s;
}

// "0x00B09D01..." or "00b09d01..." -> 64-bit GUID.
bool parseGuid(const std::string &text, uint64_t &out) {
    std::string t = text;
    if (t.size() > 2 && t[0] == '0' && (t[1] == 'x' || t[1] == 'X')) t = t.substr(2);
    if (t.empty() || t.size() > 16 || t.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos) return false;
    out = std::stoull(t, nullptr, 16);
    return true;
}

} // namespace

std::string guidText(uint64_t guid) {
    char b[32];
    std::snprintf(b, sizeof b, "0x%016llx", static_cast<unsigned long long>(guid));
    return b;
}

// ---- Splitting -------------------------------------------------------------------------------

std::string interleavedFrameProblem(uint32_t width, uint32_t height, uint32_t stride, uint32_t bitsPerPixel,
                                    uint64_t imageBytes, int decimation) {
    const std::string geometry = std::to_string(width) + "x" + std::to_string(height) + " frame of " +
                                 std::to_string(bitsPerPixel) + "-bit pixels, stride " + std::to_string(stride) + ", " +
                                 std::to_string(imageBytes) + " bytes";
    if (bitsPerPixel != 16) return geometry + ": expected 16-bit pixels (left and right bytes interleaved)";
    if (width == 0 || height == 0 || width > 32768 || height > 32768)
        return geometry + ": expected 1..32768 pixels a side";
    if (stride < 2ull * width) return geometry + ": the stride is shorter than a row of 2 x width bytes";
    const uint64_t need = static_cast<uint64_t>(stride) * (height - 1) + 2ull * width;
    if (imageBytes < need) return geometry + ": its rows need " + std::to_string(need) + " bytes";
    if (decimation < 1 || decimation > 8 || width % static_cast<uint32_t>(decimation) != 0 ||
        height % static_cast<uint32_t>(decimation) != 0)
        return geometry + ": decimation " + std::to_string(decimation) + " must be 1..8 and divide width and height";
    return "";
}

void splitInterleaved(uint8_t *image, uint32_t width, uint32_t height, uint32_t stride, int decimation,
                      bool leftIsFirstByte, std::vector<uint8_t> &scratch) {
    // Callers check first; a frame that slips through must not be read past its end.
    const uint64_t bytes = static_cast<uint64_t>(stride) * (height ? height - 1 : 0) + 2ull * width;
    if (const std::string problem = interleavedFrameProblem(width, height, stride, 16, bytes, decimation); !problem.empty())
        throw std::invalid_argument("videre1394: cannot split a " + problem);
    const size_t plane = static_cast<size_t>(width) * height;
    scratch.resize(2 * plane + 2 * static_cast<size_t>(width));
    uint8_t *first = scratch.data(), *second = scratch.data() + plane;
    if (stride == 2 * width) {
        // libdc1394 reads width x (2 height) bytes: the first byte of each pixel goes to the
        // top (first) image, the second to the bottom one.
        dc1394_deinterlace_stereo(image, scratch.data(), width, 2 * height);
    } else {
        uint8_t *row = scratch.data() + 2 * plane;
        for (uint32_t y = 0; y < height; ++y) {
            dc1394_deinterlace_stereo(image + static_cast<size_t>(y) * stride, row, width, 2);
            std::memcpy(first + static_cast<size_t>(y) * width, row, width);
            std::memcpy(second + static_cast<size_t>(y) * width, row + width, width);
        }
    }
    const int w = static_cast<int>(width), h = static_cast<int>(height);
    const cv::Mat left(h, w, CV_8UC1, leftIsFirstByte ? first : second);
    const cv::Mat right(h, w, CV_8UC1, leftIsFirstByte ? second : first);
    const int wd = w / decimation, hd = h / decimation;
    // Written back into the frame's own buffer: it holds 2 w h bytes, the images need
    // 2 wd hd. resize and copyTo write into a header of the right size in place.
    cv::Mat outLeft(hd, wd, CV_8UC1, image), outRight(hd, wd, CV_8UC1, image + static_cast<size_t>(wd) * hd);
    if (decimation == 1) {
        left.copyTo(outLeft);
        right.copyTo(outRight);
    } else {
        cv::resize(left, outLeft, outLeft.size(), 0, 0, cv::INTER_AREA); // mean of d x d blocks
        cv::resize(right, outRight, outRight.size(), 0, 0, cv::INTER_AREA);
    }
}

// ---- The capture -----------------------------------------------------------------------------

// The opened camera, shared by the source and every lent frame: a DMA buffer lent to the
// host goes back to the ring (dc1394_capture_enqueue) when the frame is released, and the
// ring is freed only once no buffer is out. Every camera call but waiting happens under
// `mutex`.
class Capture {
public:
    Capture(std::unique_ptr<Camera> camera, std::string name) : name(std::move(name)), camera_(std::move(camera)) {}

    ~Capture() {
        std::lock_guard<std::mutex> lock(mutex);
        try {
            camera_->stopTransmission();
        } catch (...) {
        }
        try {
            camera_->stopCapture();
        } catch (...) {
        }
    }

    Capture(const Capture &) = delete;
    Capture &operator=(const Capture &) = delete;

    Camera &camera() { return *camera_; }

    // A lent frame comes back (a frame's onRelease, any thread). Never throws.
    void giveBack(const RawFrame &frame) noexcept {
        std::lock_guard<std::mutex> lock(mutex);
        if (lent > 0) --lent;
        if (!capturing) return;
        if (gone.empty()) {
            try {
                camera_->enqueue(frame);
                ++enqueued;
            } catch (const DeviceError &e) {
                if (e.kind() == DeviceError::Kind::Gone)
                    gone = "videre1394: camera " + name + " went away (" + e.what() + ")";
            } catch (...) {
            }
        }
        if (lent == 0 && !transmitting) freeRingLocked();
    }

    // The DMA ring is freed when transmission stopped and no buffer is lent.
    void freeRingLocked() noexcept {
        if (!capturing) return;
        capturing = false;
        try {
            camera_->stopCapture();
        } catch (...) {
        }
    }

    std::mutex mutex;
    std::string name;           // "0x... Videre Design MDS-STH"
    bool capturing = false;     // the DMA ring exists
    bool transmitting = false;
    uint32_t lent = 0;          // buffers the host holds
    std::string gone;           // the message, once the camera went away

    // Statistics.
    uint64_t dequeued = 0, enqueued = 0, corrupt = 0;
    uint32_t framesBehind = 0, framesBehindMax = 0;

private:
    std::unique_ptr<Camera> camera_;
};

// ---- The source ------------------------------------------------------------------------------

VidereSource::VidereSource(const sdk::CheckedParams &params, sdk::Host &host)
    : host_(host), settings_(readSettings(params)) {
    std::vector<CameraInfo> cameras;
    try {
        cameras = bus().cameras();
    } catch (const DeviceError &e) {
        throw Error(BINOCLE_ERR_NOT_FOUND, std::string("videre1394: ") + e.what());
    }
    if (cameras.empty())
        throw Error(BINOCLE_ERR_NOT_FOUND, "videre1394: no IEEE-1394 camera found (bus: " + bus().describe() + ")");
    const CameraInfo chosen = choose(cameras);
    std::unique_ptr<Camera> camera;
    try {
        camera = bus().open(chosen);
    } catch (const DeviceError &e) {
        throw Error(e.kind() == DeviceError::Kind::NoBus ? BINOCLE_ERR_NOT_FOUND : BINOCLE_ERR_DEVICE,
                    "videre1394: cannot open camera " + describe(chosen) + ": " + e.what());
    }
    capture_ = std::make_shared<Capture>(std::move(camera), describe(chosen));
    selectMode();
    readCalibration();
    host_.info("videre1394: " + capture_->name + ", " + mode_.name + (mode_.format7 ? "" : " at " + number(settings_.fps) + " fps") +
               ", images " + std::to_string(outWidth_) + "x" + std::to_string(outHeight_) + ", calibration: " +
               calibrationNote_);
}

VidereSource::~VidereSource() = default;

CameraInfo VidereSource::choose(const std::vector<CameraInfo> &cameras) const {
    std::string found;
    for (const auto &c : cameras) found += (found.empty() ? "" : ", ") + describe(c);
    if (!settings_.guid.empty()) {
        uint64_t guid = 0;
        if (!parseGuid(settings_.guid, guid))
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "videre1394: guid = '" + settings_.guid +
                                                          "': expected a hexadecimal GUID such as 0x00b09d0100a1b2c3 "
                                                          "(cameras found: " + found + ")");
        for (const auto &c : cameras)
            if (c.guid == guid) return c;
        throw Error(BINOCLE_ERR_NOT_FOUND, "videre1394: no camera with GUID " + guidText(guid) + " (found: " + found + ")");
    }
    for (const auto &c : cameras)
        if (isVidere(c)) return c;
    throw Error(BINOCLE_ERR_NOT_FOUND, "videre1394: no Videre Design head among the IEEE-1394 cameras (found: " + found +
                                           "); set guid to use one of them");
}

void VidereSource::selectMode() {
    Camera &cam = capture_->camera();
    std::vector<VideoMode> modes;
    try {
        modes = cam.modes();
    } catch (const DeviceError &e) {
        throw Error(BINOCLE_ERR_DEVICE, "videre1394: camera " + capture_->name + ": cannot list its video modes: " + e.what());
    }
    auto offered = [&] {
        std::string all;
        for (const auto &m : modes) {
            std::string rates;
            for (double r : m.framerates) rates += (rates.empty() ? "" : ", ") + number(r);
            all += (all.empty() ? "" : "; ") + m.name +
                   (m.format7 ? " (" + std::to_string(m.width) + "x" + std::to_string(m.height) + " " + m.coding + ")"
                              : rates.empty() ? "" : " (" + rates + " fps)");
        }
        return all.empty() ? std::string("no video mode") : all;
    };
    auto it = std::find_if(modes.begin(), modes.end(),
                           [&](const VideoMode &m) { return lower(m.name) == lower(settings_.videoMode); });
    if (it == modes.end())
        throw Error(BINOCLE_ERR_UNSUPPORTED, "videre1394: camera " + capture_->name + " cannot do video_mode " +
                                                 settings_.videoMode + ": it offers " + offered());
    mode_ = *it;
    if (mode_.coding != "MONO16" && mode_.coding != "RAW16")
        throw Error(BINOCLE_ERR_UNSUPPORTED, "videre1394: video_mode " + mode_.name + " carries " + mode_.coding +
                                                 " pixels, but a stereo head interleaves left and right in a 16-bit "
                                                 "pixel (MONO16 or RAW16); camera " + capture_->name + " offers " +
                                                 offered());
    if (!mode_.format7) {
        const bool ok = std::any_of(mode_.framerates.begin(), mode_.framerates.end(),
                                    [&](double r) { return std::abs(r - settings_.fps) < 1e-3; });
        if (!ok) {
            std::string rates;
            for (double r : mode_.framerates) rates += (rates.empty() ? "" : ", ") + number(r);
            throw Error(BINOCLE_ERR_UNSUPPORTED, "videre1394: camera " + capture_->name + " cannot do fps " +
                                                     number(settings_.fps) + " in video_mode " + mode_.name +
                                                     ": it offers " + (rates.empty() ? "none" : rates) + " fps");
        }
    }
    const auto d = static_cast<uint32_t>(settings_.decimation);
    if (mode_.width % d != 0 || mode_.height % d != 0)
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "videre1394: decimation = " + std::to_string(d) + ": expected a divisor of " +
                                                      std::to_string(mode_.width) + " and " + std::to_string(mode_.height) +
                                                      " (the size of video_mode " + mode_.name + ")");
    outWidth_ = mode_.width / d;
    outHeight_ = mode_.height / d;
    try {
        cam.configure(mode_, settings_.fps, settings_.isoSpeedMbps);
    } catch (const DeviceError &e) {
        throw Error(BINOCLE_ERR_DEVICE, "videre1394: camera " + capture_->name + ": cannot set video_mode " + mode_.name +
                                            (mode_.format7 ? "" : " at " + number(settings_.fps) + " fps") + ": " + e.what());
    }
}

void VidereSource::readCalibration() {
    if (!settings_.useStoredCalibration) {
        calibrationNote_ = "not read (use_stored_calibration: false)";
        return;
    }
    std::string text;
    try {
        text = capture_->camera().readStoredCalibration();
    } catch (const DeviceError &e) {
        calibrationNote_ = std::string("unreadable: ") + e.what();
        host_.warning("videre1394: cannot read the calibration stored in camera " + capture_->name + ": " + e.what());
        return;
    }
    if (text.empty()) {
        calibrationNote_ = "none stored in the head";
        return;
    }
    try {
        const SvsCalibration svs = parseSvs(text);
        calibration_ = calibrationYaml(svs, static_cast<int>(outWidth_), static_cast<int>(outHeight_),
                                       "videre1394 " + guidText(capture_->camera().info().guid) + " stored calibration");
        calibrationNote_ = "stored in the head";
    } catch (const std::exception &e) {
        // A bad stored calibration does not stop capture: the rig can name a file instead.
        calibrationNote_ = std::string("unusable: ") + e.what();
        host_.warning("videre1394: the calibration stored in camera " + capture_->name + " is unusable (" + e.what() +
                      "); give the rig a calibration file");
    }
}

void VidereSource::start() {
    if (started_) return;
    Capture &c = *capture_;
    std::lock_guard<std::mutex> lock(c.mutex);
    if (!c.gone.empty()) throw Error(BINOCLE_ERR_DEVICE, c.gone);
    try {
        if (!c.capturing) {
            c.camera().setupCapture(settings_.bufferCount);
            c.capturing = true;
        }
        c.camera().startTransmission();
        c.transmitting = true;
    } catch (const DeviceError &e) {
        throw Error(BINOCLE_ERR_DEVICE,
                    "videre1394: camera " + c.name + ": cannot start capture (" + std::to_string(settings_.bufferCount) +
                        " DMA buffers, " + mode_.name + "): " + e.what() +
                        "; is the bus's isochronous bandwidth taken by another camera?");
    }
    started_ = true;
}

void VidereSource::stop() {
    if (!started_) return;
    started_ = false;
    Capture &c = *capture_;
    std::lock_guard<std::mutex> lock(c.mutex);
    c.transmitting = false;
    try {
        c.camera().stopTransmission();
    } catch (const DeviceError &) {
        // A camera that went away stopped by itself.
    }
    if (c.lent == 0) c.freeRingLocked();
}

std::unique_ptr<sdk::Frame> VidereSource::grab(int32_t timeout_ms) {
    if (!started_) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "videre1394: grab before start (or after stop)");
    checkRingHasRoom();
    const RawFrame f = nextWholeFrame(timeout_ms);
    checkFrameGeometry(f);
    return lend(f);
}

// The ring needs a buffer of its own to fill: a grab while the host holds all the others
// would wait for ever.
void VidereSource::checkRingHasRoom() const {
    Capture &c = *capture_;
    std::lock_guard<std::mutex> lock(c.mutex);
    if (!c.gone.empty()) throw Error(BINOCLE_ERR_DEVICE, c.gone);
    if (c.lent + 1 >= settings_.bufferCount)
        throw Error(BINOCLE_ERR_BUSY, "videre1394: " + std::to_string(c.lent) + " of the " +
                                          std::to_string(settings_.bufferCount) + " DMA buffers of camera " + c.name +
                                          " are lent to the host and the ring needs one to fill; release frames "
                                          "before grabbing more, or raise buffer_count");
}

// Remembered, so that every later call says why the camera is gone.
Error VidereSource::lostCamera(const DeviceError &e) {
    Capture &c = *capture_;
    std::lock_guard<std::mutex> lock(c.mutex);
    c.gone = "videre1394: camera " + c.name + " stopped delivering after " + std::to_string(c.dequeued) +
             " frames (" + e.what() + "): cable unplugged, power lost or bus reset";
    return Error(BINOCLE_ERR_DEVICE, c.gone);
}

// Takes a filled buffer off the ring, if one is there; the camera's loss is thrown as
// lostCamera() says it, any other device error as it is.
bool VidereSource::dequeue(RawFrame &f) {
    Capture &c = *capture_;
    std::optional<DeviceError> lost;
    {
        std::lock_guard<std::mutex> lock(c.mutex);
        try {
            return c.camera().dequeue(f);
        } catch (const DeviceError &e) {
            if (e.kind() != DeviceError::Kind::Gone)
                throw Error(BINOCLE_ERR_DEVICE, "videre1394: camera " + c.name + ": " + e.what());
            lost = e;
        }
    }
    throw lostCamera(*lost); // outside the lock: lostCamera takes it
}

// Counts a dequeued frame; a corrupt one goes straight back to the ring. Returns whether
// the frame is whole.
bool VidereSource::acceptDequeued(RawFrame &f) {
    Capture &c = *capture_;
    std::lock_guard<std::mutex> lock(c.mutex);
    ++c.dequeued;
    c.framesBehind = f.framesBehind;
    c.framesBehindMax = std::max(c.framesBehindMax, f.framesBehind);
    if (!f.corrupt) return true;
    ++c.corrupt;
    try {
        c.camera().enqueue(f);
    } catch (const DeviceError &) {
    }
    return false;
}

// The next frame the camera delivers whole, waiting up to timeout_ms (< 0: for ever).
RawFrame VidereSource::nextWholeFrame(int32_t timeout_ms) {
    using Clock = std::chrono::steady_clock;
    const auto deadline = Clock::now() + std::chrono::milliseconds(std::max(timeout_ms, 0));
    Capture &c = *capture_;
    RawFrame f;
    for (;;) {
        if (dequeue(f)) {
            if (acceptDequeued(f)) return f;
            if (timeout_ms >= 0 && Clock::now() > deadline)
                throw Error(BINOCLE_ERR_TIMEOUT, "videre1394: only corrupt frames from camera " + c.name + " within " +
                                                     std::to_string(timeout_ms) + " ms");
            continue;
        }
        int remaining = -1;
        if (timeout_ms >= 0)
            remaining = static_cast<int>(std::max<int64_t>(
                0, std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count()));
        bool ready = false;
        try {
            ready = c.camera().waitForFrame(remaining);
        } catch (const DeviceError &e) {
            if (e.kind() == DeviceError::Kind::Gone) throw lostCamera(e);
            throw Error(BINOCLE_ERR_DEVICE, "videre1394: camera " + c.name + ": " + e.what());
        }
        if (!ready)
            throw Error(BINOCLE_ERR_TIMEOUT, "videre1394: no frame from camera " + c.name + " within " +
                                                 std::to_string(timeout_ms) + " ms (" + mode_.name +
                                                 (mode_.format7 ? "" : " at " + number(settings_.fps) + " fps") + ")");
    }
}

// A frame of another size or depth than the mode's cannot be split: give it back.
void VidereSource::checkFrameGeometry(const RawFrame &f) {
    if (f.width == mode_.width && f.height == mode_.height &&
        interleavedFrameProblem(f.width, f.height, f.stride, f.bitsPerPixel, f.imageBytes, settings_.decimation).empty())
        return;
    Capture &c = *capture_;
    {
        std::lock_guard<std::mutex> lock(c.mutex);
        try {
            c.camera().enqueue(f);
        } catch (const DeviceError &) {
        }
    }
    const uint64_t need = static_cast<uint64_t>(mode_.width) * mode_.height * 2;
    throw Error(BINOCLE_ERR_DEVICE, "videre1394: camera " + c.name + " delivered a " + std::to_string(f.width) + "x" +
                                        std::to_string(f.height) + " frame of " + std::to_string(f.bitsPerPixel) +
                                        "-bit pixels (" + std::to_string(f.imageBytes) + " bytes), expected " +
                                        std::to_string(mode_.width) + "x" + std::to_string(mode_.height) +
                                        " of 16-bit pixels (" + std::to_string(need) + " bytes) for " + mode_.name);
}

// Splits the frame in its own DMA buffer and lends that buffer to the host: it returns
// to the ring when the host releases the frame.
std::unique_ptr<sdk::Frame> VidereSource::lend(const RawFrame &f) {
    splitInterleaved(f.image, f.width, f.height, f.stride, settings_.decimation, settings_.leftIsFirstByte, scratch_);
    {
        std::lock_guard<std::mutex> lock(capture_->mutex);
        ++capture_->lent;
    }
    auto frame = std::make_unique<sdk::Frame>();
    const int32_t w = static_cast<int32_t>(outWidth_), h = static_cast<int32_t>(outHeight_);
    frame->left = sdk::makeImage(w, h, BINOCLE_PIXEL_GRAY8, f.image, w);
    frame->right = sdk::makeImage(w, h, BINOCLE_PIXEL_GRAY8, f.image + static_cast<size_t>(w) * h, w);
    frame->sequence = sequence_++;
    frame->timestamp_left_ns = frame->timestamp_right_ns = static_cast<int64_t>(f.timestampUs) * 1000;
    std::shared_ptr<Capture> keep = capture_;
    frame->onRelease = [keep, f]() { keep->giveBack(f); };

    YAML::Emitter meta;
    meta << YAML::BeginMap;
    meta << YAML::Key << "guid" << YAML::Value << guidText(capture_->camera().info().guid);
    meta << YAML::Key << "video_mode" << YAML::Value << mode_.name;
    meta << YAML::Key << "decimation" << YAML::Value << settings_.decimation;
    meta << YAML::Key << "frames_behind" << YAML::Value << f.framesBehind;
    meta << YAML::EndMap;
    frame->metadata = meta.c_str();
    return frame;
}

std::string VidereSource::statistics() {
    Capture &c = *capture_;
    std::lock_guard<std::mutex> lock(c.mutex);
    const CameraInfo info = c.camera().info();
    YAML::Emitter out;
    out << YAML::BeginMap;
    out << YAML::Key << "live" << YAML::Value << true; // the host defaults to the latest policy
    out << YAML::Key << "guid" << YAML::Value << guidText(info.guid);
    out << YAML::Key << "vendor" << YAML::Value << info.vendor;
    out << YAML::Key << "model" << YAML::Value << info.model;
    out << YAML::Key << "video_mode" << YAML::Value << mode_.name;
    out << YAML::Key << "fps" << YAML::Value << (mode_.format7 ? 0.0 : settings_.fps);
    out << YAML::Key << "decimation" << YAML::Value << settings_.decimation;
    out << YAML::Key << "image_size" << YAML::Value << std::to_string(outWidth_) + "x" + std::to_string(outHeight_);
    out << YAML::Key << "left_byte" << YAML::Value << (settings_.leftIsFirstByte ? "first" : "second");
    out << YAML::Key << "frames" << YAML::Value << sequence_;
    out << YAML::Key << "dequeued" << YAML::Value << c.dequeued;
    out << YAML::Key << "enqueued_on_release" << YAML::Value << c.enqueued;
    out << YAML::Key << "corrupt" << YAML::Value << c.corrupt;
    out << YAML::Key << "frames_behind" << YAML::Value << c.framesBehind;
    out << YAML::Key << "frames_behind_max" << YAML::Value << c.framesBehindMax;
    out << YAML::Key << "buffers" << YAML::Value << settings_.bufferCount;
    out << YAML::Key << "lent" << YAML::Value << c.lent;
    out << YAML::Key << "stored_calibration" << YAML::Value << calibrationNote_;
    if (!c.gone.empty()) out << YAML::Key << "gone" << YAML::Value << c.gone;
    out << YAML::EndMap;
    return out.c_str();
}

std::string VidereSource::enumerateDevices(sdk::Host &host) {
    std::vector<CameraInfo> cameras;
    try {
        cameras = bus().cameras();
    } catch (const DeviceError &e) {
        host.info(std::string("videre1394: ") + e.what());
    }
    YAML::Emitter out;
    out << YAML::BeginSeq;
    for (const CameraInfo &c : cameras) {
        out << YAML::BeginMap;
        out << YAML::Key << "id" << YAML::Value << guidText(c.guid);
        out << YAML::Key << "description" << YAML::Value << (c.vendor + " " + c.model);
        out << YAML::Key << "guid" << YAML::Value << guidText(c.guid);
        out << YAML::Key << "unit" << YAML::Value << c.unit;
        out << YAML::Key << "vendor" << YAML::Value << c.vendor;
        out << YAML::Key << "model" << YAML::Value << c.model;
        out << YAML::Key << "videre" << YAML::Value << isVidere(c);
        out << YAML::EndMap;
    }
    out << YAML::EndSeq;
    return out.c_str();
}

} // namespace binocle::videre1394
