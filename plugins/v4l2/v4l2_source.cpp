// SPDX-License-Identifier: MIT
// v4l2: the logic of the plugin: settings, format negotiation, memory-mapped streaming,
// pairing of two devices by time stamp, side-by-side splitting, conversion, lending of
// buffers and the errors a user reads.
//
// Read top to bottom: settings, conversion, the source. One opened device (Stream) and
// the errors a user reads from the kernel's answers are in v4l2_stream.*.
#include "v4l2_source.hpp"
#include "v4l2_stream.hpp"

#include <linux/videodev2.h>

#include <binocle/settings.hpp>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>
#include <utility>

namespace binocle::v4l2 {

using sdk::Error;

// ---- Settings ------------------------------------------------------------------------------

std::vector<binocle_param_desc> V4l2Source::parameters() {
    using sdk::Param;
    return {
        Param::choice("layout", "two_devices", "two_devices|side_by_side")
            .help("two_devices: one device per imager; side_by_side: one device whose frames hold the left "
                  "image in their left half and the right image in their right half"),
        Param::string("device_left", "/dev/video0")
            .help("device of the left (reference) imager; with side_by_side, the one device"),
        Param::string("device_right", "/dev/video1").help("two_devices: device of the right imager"),
        Param::boolean("swap_halves", false).help("side_by_side: the left image is the right half of the frame"),
        Param::choice("pixel_format", "yuyv", "grey|yuyv|mjpeg")
            .help("what the device delivers: GREY (8-bit, lent without copy), YUYV 4:2:2 or Motion-JPEG"),
        Param::choice("color", "gray", "gray|bgr").help("images handed to the pipeline: GRAY8 or BGR8"),
        Param::integer("width", "640").min(2).max(16384).unit("px")
            .help("width of each device's frame (side_by_side: both halves together)"),
        Param::integer("height", "480").min(1).max(16384).unit("px").help("height of each device's frame"),
        Param::real("fps", "30").min(0).max(1000).unit("Hz")
            .help("frame rate asked of each device (VIDIOC_S_PARM); 0 keeps the driver's"),
        Param::integer("buffer_count", "4").min(2).max(32)
            .help("memory-mapped buffers per device (VIDIOC_REQBUFS)"),
        Param::real("pair_tolerance_ms", "0").min(0).max(1e6).unit("ms")
            .help("two_devices: largest time-stamp difference within a pair; 0 = half the frame period"),
    };
}

namespace {

using Clock = std::chrono::steady_clock;

std::string sizeText(uint32_t w, uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }

std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

// The table above is the one home of each setting's default, bounds and choices: the
// SDK checked `c` against it before the constructor (a setting the host did not pass is
// its default). Only the rules across settings are written here.
Settings readSettings(const sdk::CheckedParams &c) {
    Settings s;
    s.sideBySide = c.string("layout") == "side_by_side";
    s.deviceLeft = c.string("device_left");
    s.deviceRight = c.string("device_right");
    s.swapHalves = c.boolean("swap_halves");
    const std::string &format = c.string("pixel_format");
    s.fourcc = format == "grey" ? V4L2_PIX_FMT_GREY : format == "mjpeg" ? V4L2_PIX_FMT_MJPEG : V4L2_PIX_FMT_YUYV;
    s.bgr = c.string("color") == "bgr";
    s.width = static_cast<uint32_t>(c.integer("width"));
    s.height = static_cast<uint32_t>(c.integer("height"));
    s.fps = c.real("fps");
    s.bufferCount = static_cast<uint32_t>(c.integer("buffer_count"));
    s.pairToleranceMs = c.real("pair_tolerance_ms");

    if (s.deviceLeft.empty()) c.refuse("device_left", "''", "a device path such as /dev/video0");
    if (s.sideBySide) {
        if (s.width % 2 != 0)
            c.refuse("width", std::to_string(s.width), "an even width with layout side_by_side (two halves of width/2)");
    } else {
        if (s.deviceRight.empty()) c.refuse("device_right", "''", "a device path such as /dev/video1");
        if (s.deviceRight == s.deviceLeft)
            c.refuse("device_right", s.deviceRight,
                     "another device than device_left with layout two_devices (one device delivering both images is "
                     "layout side_by_side)");
    }
    return s;
}

int bytesPerPixel(uint32_t fourcc) {
    switch (fourcc) {
    case V4L2_PIX_FMT_GREY: return 1;
    case V4L2_PIX_FMT_YUYV: return 2;
    default: return 0; // compressed
    }
}

std::string formatText(const PixFormat &f) { return fourccText(f.fourcc) + " " + sizeText(f.width, f.height); }

// "YUYV 640x480, 320x240; MJPG 1280x480": formats a device offers, as a user sets them.
std::string offersText(const std::vector<FormatDesc> &formats) {
    std::string out;
    for (const FormatDesc &f : formats) {
        if (f.emulated) continue; // software conversions of libv4l2, not what the device does
        std::string sizes;
        for (const FrameSize &s : f.sizes) sizes += (sizes.empty() ? "" : ", ") + sizeText(s.width, s.height);
        out += (out.empty() ? "" : "; ") + fourccText(f.fourcc) + (sizes.empty() ? "" : " " + sizes);
    }
    return out.empty() ? "no capture format" : out;
}

// Unpaired frames in a row after which two devices are taken as never agreeing.
constexpr int kMaxUnpairedInARow = 1000;

int64_t nowNs() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

} // namespace

// ---- The source --------------------------------------------------------------------------------

V4l2Source::V4l2Source(const sdk::CheckedParams &params, sdk::Host &host) : host_(host), settings_(readSettings(params)) {
    if (settings_.sideBySide) {
        streams_.push_back(openStream(settings_.deviceLeft, "side_by_side"));
    } else {
        streams_.push_back(openStream(settings_.deviceLeft, "left"));
        streams_.push_back(openStream(settings_.deviceRight, "right"));
    }
    double fps = 0;
    for (const auto &s : streams_)
        if (s->fpsGranted > 0) fps = fps > 0 ? std::min(fps, s->fpsGranted) : s->fpsGranted;
    if (fps <= 0) fps = settings_.fps > 0 ? settings_.fps : 30.0;
    toleranceNs_ = settings_.pairToleranceMs > 0 ? static_cast<int64_t>(settings_.pairToleranceMs * 1e6)
                                                 : static_cast<int64_t>(0.5e9 / fps);
    std::string what;
    for (const auto &s : streams_) what += (what.empty() ? "" : ", ") + s->path + " (" + s->role + ")";
    host_.info("v4l2: " + what + ": " + formatText(streams_.front()->format) +
               (zeroCopy() ? ", lent without copy" : ", converted to " + std::string(settings_.bgr ? "BGR8" : "GRAY8")));
}

V4l2Source::~V4l2Source() = default;

std::shared_ptr<Stream> V4l2Source::openStream(const std::string &path, const std::string &role) {
    std::unique_ptr<Device> device;
    try {
        device = deviceSystem().open(path);
    } catch (const DeviceError &e) {
        throwFor(path, e, "opening the " + role + " device");
    }
    auto stream = std::make_shared<Stream>(std::move(device), role);
    Device &d = stream->device();
    const Settings &s = settings_;

    try {
        stream->capability = d.queryCapability();
    } catch (const DeviceError &e) {
        throwFor(path, e, "asking its capabilities");
    }
    const Capability &cap = stream->capability;
    const std::string name = path + " (" + cap.card + ", driver " + cap.driver + ")";
    if (!(cap.capabilities & V4L2_CAP_VIDEO_CAPTURE))
        throw Error(BINOCLE_ERR_UNSUPPORTED, "v4l2: " + name + " is not a video capture device (capabilities 0x" +
                                                 [&] {
                                                     std::ostringstream h;
                                                     h << std::hex << cap.capabilities;
                                                     return h.str();
                                                 }() + "); metadata and output nodes of a camera cannot be " +
                                                 "opened as a source, try the next /dev/video*");
    if (!(cap.capabilities & V4L2_CAP_STREAMING))
        throw Error(BINOCLE_ERR_UNSUPPORTED,
                    "v4l2: " + name + " cannot stream (no V4L2_CAP_STREAMING): memory-mapped streaming is needed");

    PixFormat want;
    want.fourcc = s.fourcc;
    want.width = s.width;
    want.height = s.height;
    const std::string asked = formatText(want);
    PixFormat got;
    try {
        got = d.setFormat(want);
    } catch (const DeviceError &e) {
        throwFor(path, e, "setting the format " + asked);
    }
    if (got.fourcc != want.fourcc || got.width != want.width || got.height != want.height) {
        std::string offers;
        try {
            offers = offersText(d.formats());
        } catch (const DeviceError &e) {
            offers = std::string("(cannot list them: ") + e.what() + ")";
        }
        throw Error(BINOCLE_ERR_UNSUPPORTED, "v4l2: " + path + " cannot deliver " + asked + ": it offers " + offers +
                                                 " (the driver proposed " + formatText(got) +
                                                 "); set pixel_format, width and height to one of these");
    }
    if (const int bpp = bytesPerPixel(got.fourcc)) {
        // Drivers fill these in; a zero one is taken as tightly packed.
        if (got.bytesPerLine == 0) got.bytesPerLine = got.width * bpp;
        if (got.sizeImage == 0) got.sizeImage = got.bytesPerLine * got.height;
        if (got.bytesPerLine < got.width * static_cast<uint32_t>(bpp) || got.sizeImage < got.bytesPerLine * got.height)
            throw Error(BINOCLE_ERR_DEVICE, "v4l2: " + path + ": the driver's " + asked + " has " +
                                                std::to_string(got.bytesPerLine) + " bytes per line and " +
                                                std::to_string(got.sizeImage) + " bytes per image, too few for " +
                                                std::to_string(bpp) + " bytes per pixel");
    }
    stream->format = got;

    if (s.fps > 0) {
        try {
            stream->fpsGranted = d.setFrameRate(s.fps);
        } catch (const DeviceError &e) {
            if (e.err() == EBUSY || e.err() == ENODEV) throwFor(path, e, "setting the frame rate");
            host_.warning("v4l2: " + path + ": cannot set the frame rate to " + number(s.fps) + " fps (" + e.what() +
                          "); the driver keeps its own");
        }
        if (stream->fpsGranted <= 0)
            host_.warning("v4l2: " + path + " does not let the frame rate be set; fps " + number(s.fps) + " is ignored");
        else if (std::abs(stream->fpsGranted - s.fps) > 0.01 * s.fps)
            host_.warning("v4l2: " + path + " runs at " + number(stream->fpsGranted) + " fps, not the " + number(s.fps) +
                          " fps asked (it offers no closer rate for " + asked + ")");
    }
    return stream;
}

bool V4l2Source::zeroCopy() const { return settings_.fourcc == V4L2_PIX_FMT_GREY && !settings_.bgr; }

void V4l2Source::start() {
    if (started_) return;
    for (const auto &sp : streams_) {
        Stream &st = *sp;
        std::lock_guard<std::mutex> lock(st.mutex);
        if (!st.gone.empty()) throw Error(BINOCLE_ERR_DEVICE, st.gone);
        if (st.streaming) continue; // started by an earlier start that failed on the other device
        Device &d = st.device();
        try {
            if (st.buffers.empty()) {
                const uint32_t granted = d.requestBuffers(settings_.bufferCount);
                if (granted < 2)
                    throw Error(BINOCLE_ERR_DEVICE, "v4l2: " + st.path + " granted " + std::to_string(granted) +
                                                        " buffers for buffer_count " +
                                                        std::to_string(settings_.bufferCount) + "; at least 2 are needed");
                for (uint32_t i = 0; i < granted; ++i) {
                    Mapping m = d.mapBuffer(i);
                    const uint32_t need = bytesPerPixel(st.format.fourcc) ? st.format.bytesPerLine * st.format.height : 1;
                    if (m.length < need)
                        throw Error(BINOCLE_ERR_DEVICE, "v4l2: " + st.path + ": buffer " + std::to_string(i) + " holds " +
                                                            std::to_string(m.length) + " bytes, less than the " +
                                                            std::to_string(need) + " of one " + formatText(st.format) +
                                                            " frame");
                    st.buffers.push_back(m);
                }
                st.lent.assign(granted, 0);
            }
            // A buffer still lent from before a stop is queued when it comes back.
            for (uint32_t i = 0; i < st.buffers.size(); ++i)
                if (!st.lent[i]) d.queueBuffer(i);
            d.streamOn();
            st.streaming = true;
        } catch (const DeviceError &e) {
            st.failLocked(e, "starting to stream");
        }
    }
    pending_ = {};
    started_ = true;
}

void V4l2Source::stop() {
    for (const auto &sp : streams_) {
        Stream &st = *sp;
        std::lock_guard<std::mutex> lock(st.mutex);
        if (!st.streaming) continue;
        st.streaming = false; // every buffer is ours again, lent ones included
        try {
            st.device().streamOff();
        } catch (const DeviceError &) {
            // A device that went away stops by itself; nothing to undo.
        }
    }
    pending_ = {};
    started_ = false;
}

// The next good buffer of streams_[which], or an error. Corrupt buffers
// (V4L2_BUF_FLAG_ERROR) are given back and counted.
Dequeued V4l2Source::fetch(size_t which, int64_t deadlineNs, int32_t timeoutMs) {
    Stream &st = *streams_[which];
    bool pollError = false;
    for (;;) {
        Dequeued d;
        bool got = false;
        {
            std::lock_guard<std::mutex> lock(st.mutex);
            if (!st.gone.empty()) throw Error(BINOCLE_ERR_DEVICE, st.gone);
            try {
                got = st.device().dequeueBuffer(d);
            } catch (const DeviceError &e) {
                st.failLocked(e, "taking a frame");
            }
            if (got) {
                ++st.dequeued;
                if (st.lastSequence >= 0 && d.sequence > st.lastSequence + 1)
                    st.droppedByDriver += d.sequence - static_cast<uint64_t>(st.lastSequence) - 1;
                st.lastSequence = d.sequence;
            }
        }
        if (got) {
            if (d.index >= st.buffers.size())
                throw Error(BINOCLE_ERR_DEVICE, "v4l2: " + st.path + " returned buffer " + std::to_string(d.index) +
                                                    " but only " + std::to_string(st.buffers.size()) + " were requested");
            if (d.flags & V4L2_BUF_FLAG_ERROR) {
                {
                    std::lock_guard<std::mutex> lock(st.mutex);
                    ++st.corrupt;
                }
                st.requeue(d.index);
                if (timeoutMs >= 0 && nowNs() > deadlineNs)
                    throw Error(BINOCLE_ERR_TIMEOUT, "v4l2: only corrupt frames (V4L2_BUF_FLAG_ERROR) from " + st.path +
                                                         " within " + std::to_string(timeoutMs) + " ms");
                continue;
            }
            const PixFormat &f = st.format;
            const size_t capacity = st.buffers[d.index].length;
            const uint32_t need = bytesPerPixel(f.fourcc) ? f.bytesPerLine * f.height : 1;
            if (d.bytesUsed < need || d.bytesUsed > capacity) {
                st.requeue(d.index);
                throw Error(BINOCLE_ERR_DEVICE,
                            "v4l2: " + st.path + " delivered a frame of " + std::to_string(d.bytesUsed) +
                                " bytes (driver sequence " + std::to_string(d.sequence) + "), expected " +
                                (bytesPerPixel(f.fourcc) ? std::to_string(need) + " for " + formatText(f) + " (" +
                                                               std::to_string(f.bytesPerLine) + " bytes per line)"
                                                         : "1 to " + std::to_string(capacity) + " for " + formatText(f)));
            }
            return d;
        }
        if (pollError)
            throw Error(BINOCLE_ERR_DEVICE, "v4l2: " + st.path + " (" + st.role +
                                                "): poll reported an error and no frame is ready (is it still streaming?)");
        int remaining = -1;
        if (timeoutMs >= 0) remaining = static_cast<int>(std::max<int64_t>(0, (deadlineNs - nowNs()) / 1000000));
        Wait w;
        try {
            w = st.device().waitForFrame(remaining);
        } catch (const DeviceError &e) {
            std::lock_guard<std::mutex> lock(st.mutex);
            st.failLocked(e, "waiting for a frame");
        }
        if (w == Wait::Timeout)
            throw Error(BINOCLE_ERR_TIMEOUT, "v4l2: no frame from " + st.path + " (" + st.role + ") within " +
                                                 std::to_string(timeoutMs) + " ms (" + formatText(st.format) +
                                                 (st.fpsGranted > 0 ? " at " + number(st.fpsGranted) + " fps" : "") + ")");
        if (w == Wait::Error) pollError = true; // the next dequeue says why (ENODEV ...)
    }
}

std::unique_ptr<sdk::Frame> V4l2Source::grab(int32_t timeout_ms) {
    if (!started_) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "v4l2: grab before start (or after stop)");
    if (zeroCopy()) {
        for (const auto &sp : streams_) {
            std::lock_guard<std::mutex> lock(sp->mutex);
            const auto total = static_cast<uint32_t>(sp->buffers.size());
            if (sp->lentCount() + 1 >= total)
                throw Error(BINOCLE_ERR_BUSY, "v4l2: " + std::to_string(sp->lentCount()) + " of the " +
                                                  std::to_string(total) + " buffers of " + sp->path +
                                                  " are lent to the host and the driver needs one to fill; release "
                                                  "frames before grabbing more, or raise buffer_count");
        }
    }
    const int64_t deadline = timeout_ms >= 0 ? nowNs() + static_cast<int64_t>(timeout_ms) * 1000000 : 0;

    std::array<std::optional<Dequeued>, 2> taken;
    if (settings_.sideBySide) {
        taken[0] = fetch(0, deadline, timeout_ms);
    } else {
        // Pairing: hold one buffer per device; while their time stamps differ by more
        // than the tolerance, the older one has no partner: count it, give it back.
        for (int rejected = 0;; ++rejected) {
            for (size_t i = 0; i < 2; ++i)
                if (!pending_[i]) pending_[i] = fetch(i, deadline, timeout_ms);
            const int64_t dt = pending_[0]->timestampNs - pending_[1]->timestampNs;
            if (std::llabs(dt) <= toleranceNs_) break;
            // Devices that keep delivering but never agree would keep us here for ever.
            const bool late = timeout_ms >= 0 && nowNs() > deadline;
            if (late || rejected >= kMaxUnpairedInARow)
                throw Error(late ? BINOCLE_ERR_TIMEOUT : BINOCLE_ERR_DEVICE,
                            "v4l2: no pair of frames within pair_tolerance_ms " + number(toleranceNs_ / 1e6) +
                                (late ? " in " + std::to_string(timeout_ms) + " ms"
                                      : " in " + std::to_string(kMaxUnpairedInARow) + " frames") +
                                ": the time stamps of " + streams_[0]->path + " and " + streams_[1]->path +
                                " differ by " + number(static_cast<double>(dt) / 1e6) +
                                " ms (do both drivers stamp with the same clock?)");
            const size_t older = dt < 0 ? 0 : 1;
            {
                std::lock_guard<std::mutex> lock(streams_[older]->mutex);
                ++streams_[older]->unpaired;
            }
            const uint32_t index = pending_[older]->index;
            pending_[older].reset();
            streams_[older]->requeue(index);
        }
        taken = pending_;
        pending_ = {};
    }
    return makeFrame(taken);
}

namespace {

// The pixels of one buffer, converted to GRAY8 or BGR8 in a new image.
cv::Mat convert(const Stream &st, const Dequeued &d, bool bgr) {
    const PixFormat &f = st.format;
    const uint8_t *data = st.buffers[d.index].data;
    const int w = static_cast<int>(f.width), h = static_cast<int>(f.height);
    cv::Mat out;
    try {
        switch (f.fourcc) {
        case V4L2_PIX_FMT_GREY: {
            const cv::Mat src(h, w, CV_8UC1, const_cast<uint8_t *>(data), f.bytesPerLine);
            if (bgr) cv::cvtColor(src, out, cv::COLOR_GRAY2BGR);
            else out = src.clone();
            break;
        }
        case V4L2_PIX_FMT_YUYV: {
            const cv::Mat src(h, w, CV_8UC2, const_cast<uint8_t *>(data), f.bytesPerLine);
            cv::cvtColor(src, out, bgr ? cv::COLOR_YUV2BGR_YUYV : cv::COLOR_YUV2GRAY_YUYV);
            break;
        }
        case V4L2_PIX_FMT_MJPEG: {
            const cv::Mat encoded(1, static_cast<int>(d.bytesUsed), CV_8UC1, const_cast<uint8_t *>(data));
            out = cv::imdecode(encoded, bgr ? cv::IMREAD_COLOR : cv::IMREAD_GRAYSCALE);
            if (out.empty())
                throw Error(BINOCLE_ERR_DEVICE, "v4l2: " + st.path + ": cannot decode the Motion-JPEG frame of " +
                                                    std::to_string(d.bytesUsed) + " bytes (driver sequence " +
                                                    std::to_string(d.sequence) + ")");
            if (out.cols != w || out.rows != h)
                throw Error(BINOCLE_ERR_DEVICE, "v4l2: " + st.path + ": a Motion-JPEG frame (driver sequence " +
                                                    std::to_string(d.sequence) + ") decodes to " +
                                                    sizeText(out.cols, out.rows) + ", expected " + sizeText(f.width, f.height));
            break;
        }
        default:
            throw Error(BINOCLE_ERR_INTERNAL, "v4l2: no conversion from " + fourccText(f.fourcc));
        }
    } catch (const cv::Exception &e) {
        throw Error(BINOCLE_ERR_DEVICE, "v4l2: " + st.path + ": converting a " + formatText(f) + " frame failed: " + e.err);
    }
    return out;
}

binocle_image imageOf(const cv::Mat &m, int32_t format) {
    return sdk::makeImage(m.cols, m.rows, format, m.data, static_cast<int32_t>(m.step[0]));
}

} // namespace

std::unique_ptr<sdk::Frame> V4l2Source::makeFrame(const std::array<std::optional<Dequeued>, 2> &taken) {
    auto frame = std::make_unique<sdk::Frame>();
    const int32_t format = settings_.bgr ? BINOCLE_PIXEL_BGR8 : BINOCLE_PIXEL_GRAY8;
    const size_t n = settings_.sideBySide ? 1 : 2;

    // Either lend the mapped buffers themselves (GREY delivered as GRAY8) or convert
    // into new images and give the buffers back at once.
    cv::Mat images[2];
    if (zeroCopy()) {
        for (size_t i = 0; i < n; ++i) {
            Stream &st = *streams_[i];
            std::lock_guard<std::mutex> lock(st.mutex);
            st.lent[taken[i]->index] = 1;
            images[i] = cv::Mat(static_cast<int>(st.format.height), static_cast<int>(st.format.width), CV_8UC1,
                                st.buffers[taken[i]->index].data, st.format.bytesPerLine);
        }
        std::vector<std::pair<std::shared_ptr<Stream>, uint32_t>> held;
        for (size_t i = 0; i < n; ++i) held.emplace_back(streams_[i], taken[i]->index);
        frame->onRelease = [held]() {
            for (const auto &h : held) h.first->giveBack(h.second);
        };
    } else {
        for (size_t i = 0; i < n; ++i) {
            Stream &st = *streams_[i];
            try {
                images[i] = convert(st, *taken[i], settings_.bgr);
            } catch (...) {
                for (size_t j = i; j < n; ++j) streams_[j]->requeue(taken[j]->index);
                throw;
            }
            st.requeue(taken[i]->index);
        }
        frame->owner = std::make_shared<std::vector<cv::Mat>>(std::vector<cv::Mat>{images[0], images[1]});
    }

    cv::Mat left = images[0], right = images[1];
    if (settings_.sideBySide) {
        const int half = images[0].cols / 2;
        left = images[0].colRange(0, half);
        right = images[0].colRange(half, 2 * half);
        if (settings_.swapHalves) std::swap(left, right);
    }
    frame->left = imageOf(left, format);
    frame->right = imageOf(right, format);
    frame->sequence = sequence_++;
    frame->timestamp_left_ns = taken[0]->timestampNs;
    frame->timestamp_right_ns = taken[n - 1]->timestampNs;

    YAML::Emitter meta;
    meta << YAML::BeginMap;
    if (settings_.sideBySide) {
        meta << YAML::Key << "device" << YAML::Value << streams_[0]->path;
        meta << YAML::Key << "driver_sequence" << YAML::Value << taken[0]->sequence;
    } else {
        meta << YAML::Key << "device_left" << YAML::Value << streams_[0]->path;
        meta << YAML::Key << "device_right" << YAML::Value << streams_[1]->path;
        meta << YAML::Key << "driver_sequence_left" << YAML::Value << taken[0]->sequence;
        meta << YAML::Key << "driver_sequence_right" << YAML::Value << taken[1]->sequence;
    }
    meta << YAML::EndMap;
    frame->metadata = meta.c_str();
    return frame;
}

std::string V4l2Source::statistics() {
    YAML::Emitter out;
    out << YAML::BeginMap;
    out << YAML::Key << "live" << YAML::Value << true; // the host defaults to the latest policy
    out << YAML::Key << "layout" << YAML::Value << (settings_.sideBySide ? "side_by_side" : "two_devices");
    out << YAML::Key << "pixel_format" << YAML::Value << fourccText(settings_.fourcc);
    out << YAML::Key << "color" << YAML::Value << (settings_.bgr ? "bgr" : "gray");
    out << YAML::Key << "zero_copy" << YAML::Value << zeroCopy();
    out << YAML::Key << "frames" << YAML::Value << sequence_;
    out << YAML::Key << "pair_tolerance_ms" << YAML::Value << static_cast<double>(toleranceNs_) / 1e6;
    std::vector<uint64_t> unpaired;
    out << YAML::Key << "devices" << YAML::Value << YAML::BeginSeq;
    for (const auto &sp : streams_) {
        std::lock_guard<std::mutex> lock(sp->mutex);
        unpaired.push_back(sp->unpaired);
        out << YAML::BeginMap;
        out << YAML::Key << "path" << YAML::Value << sp->path;
        out << YAML::Key << "role" << YAML::Value << sp->role;
        out << YAML::Key << "card" << YAML::Value << sp->capability.card;
        out << YAML::Key << "format" << YAML::Value << formatText(sp->format);
        out << YAML::Key << "fps" << YAML::Value << sp->fpsGranted;
        out << YAML::Key << "buffers" << YAML::Value << sp->buffers.size();
        out << YAML::Key << "lent" << YAML::Value << sp->lentCount();
        out << YAML::Key << "frames" << YAML::Value << sp->dequeued;
        out << YAML::Key << "unpaired" << YAML::Value << sp->unpaired;
        out << YAML::Key << "corrupt" << YAML::Value << sp->corrupt;
        out << YAML::Key << "dropped_by_driver" << YAML::Value << sp->droppedByDriver;
        out << YAML::Key << "requeued" << YAML::Value << sp->requeued;
        if (!sp->gone.empty()) out << YAML::Key << "gone" << YAML::Value << sp->gone;
        out << YAML::EndMap;
    }
    out << YAML::EndSeq;
    if (!settings_.sideBySide) {
        out << YAML::Key << "unpaired_left" << YAML::Value << unpaired[0];
        out << YAML::Key << "unpaired_right" << YAML::Value << unpaired[1];
    }
    out << YAML::Key << "unpaired" << YAML::Value << (unpaired.size() > 1 ? unpaired[0] + unpaired[1] : 0);
    out << YAML::EndMap;
    return out.c_str();
}

std::string V4l2Source::enumerateDevices(sdk::Host &host) {
    YAML::Emitter out;
    out << YAML::BeginSeq;
    for (const std::string &path : deviceSystem().listDevices()) {
        out << YAML::BeginMap;
        out << YAML::Key << "id" << YAML::Value << path;
        try {
            std::unique_ptr<Device> d = deviceSystem().open(path);
            const Capability cap = d->queryCapability();
            const bool capture = (cap.capabilities & V4L2_CAP_VIDEO_CAPTURE) != 0;
            const bool streaming = (cap.capabilities & V4L2_CAP_STREAMING) != 0;
            out << YAML::Key << "description" << YAML::Value
                << cap.card + " (" + cap.driver + ", " + cap.busInfo + ")" +
                       (capture ? "" : ": not a capture node");
            out << YAML::Key << "driver" << YAML::Value << cap.driver;
            out << YAML::Key << "card" << YAML::Value << cap.card;
            out << YAML::Key << "bus_info" << YAML::Value << cap.busInfo;
            out << YAML::Key << "capture" << YAML::Value << capture;
            out << YAML::Key << "streaming" << YAML::Value << streaming;
            out << YAML::Key << "formats" << YAML::Value << YAML::BeginSeq;
            if (capture)
                for (const FormatDesc &f : d->formats()) {
                    if (f.emulated) continue;
                    std::string sizes;
                    for (const FrameSize &s : f.sizes) sizes += (sizes.empty() ? "" : ", ") + sizeText(s.width, s.height);
                    out << fourccText(f.fourcc) + (sizes.empty() ? "" : " " + sizes);
                }
            out << YAML::EndSeq;
        } catch (const DeviceError &e) {
            out << YAML::Key << "description" << YAML::Value << std::string("cannot open: ") + e.what();
            host.warning("v4l2: " + path + ": " + e.what());
        }
        out << YAML::EndMap;
    }
    out << YAML::EndSeq;
    return out.c_str();
}

} // namespace binocle::v4l2
