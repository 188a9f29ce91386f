// SPDX-License-Identifier: MIT
// The `gige` StereoSource: a stereo rig of two GigE Vision cameras, or one camera that
// delivers both images side by side, through Aravis 0.8. Pairs are formed by time stamp
// (pairing.hpp); a camera that stops answering is reported and reconnected in the
// background (reconnection.hpp), and no wait lasts longer than grab's timeout. Settings and
// behaviour: README.md beside this file.
#include "gige_camera.hpp"
#include "gige_slot.hpp"
#include "pairing.hpp"
#include "pixel_formats.hpp"
#include "reconnection.hpp"

#include <binocle/plugin.hpp>
#include <opencv2/core.hpp>
#include <yaml-cpp/yaml.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

namespace binocle::gige {

namespace {

using sdk::Error;
using sdk::Param;
using std::chrono::milliseconds;

std::string readFile(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(BINOCLE_ERR_NOT_FOUND, "gige: calibration = " + path + ": the file cannot be read");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string formatMs(double ms) {
    std::ostringstream s;
    s.precision(ms < 10 ? 2 : 0);
    s << std::fixed << ms;
    return s.str();
}

} // namespace

class GigeSource : public sdk::StereoSource {
public:
    static std::vector<binocle_param_desc> parameters() {
        return {
            Param::choice("layout", "two_cameras", "two_cameras|side_by_side")
                .help("two_cameras: camera_left and camera_right; side_by_side: one camera, left half | right half"),
            Param::string("camera_left", "").help("two_cameras: device id or IP address of the left (reference) camera"),
            Param::string("camera_right", "").help("two_cameras: device id or IP address of the right camera"),
            Param::string("camera", "").help("side_by_side: device id or IP address of the camera"),
            Param::choice("pixel_format", "Mono8", pixelFormatChoices())
                .help("GenICam PixelFormat; Mono8 and BGR8 are lent without copy, the others are converted to BGR8"),
            Param::integer("width", "0").min(0).unit("px").help("Width of each camera's image (side_by_side: both halves); 0 = keep"),
            Param::integer("height", "0").min(0).unit("px").help("Height of each camera's image; 0 = keep"),
            Param::real("exposure_us", "0").min(0).unit("us").help("ExposureTime, auto exposure off; 0 = keep"),
            Param::real("gain_db", "0").unit("dB").help("Gain, auto gain off; set only when given"),
            Param::real("frame_rate_hz", "0").min(0).unit("Hz").help("AcquisitionFrameRate (free_run); 0 = keep"),
            Param::choice("trigger", "free_run", "free_run|software|hardware")
                .help("free_run: cameras stream; software: grab triggers both; hardware: trigger_line"),
            Param::string("trigger_line", "Line0").help("hardware: the TriggerSource (Line0, Line1 ...)"),
            Param::real("pair_tolerance_ms", "5").min(0).unit("ms").help("largest left/right time stamp difference of a pair"),
            Param::choice("timestamp", "system", "system|device")
                .help("system: host time at arrival (one clock for both cameras); device: the cameras' own clocks (PTP)"),
            Param::integer("lost_after_ms", "1000").min(50).unit("ms")
                .help("a camera that delivers no image this long while it should (free_run, or a software trigger) is lost"),
            Param::boolean("reconnect", true).help("reopen a lost camera in the background when it answers again"),
            Param::integer("retry_interval_ms", "1000").min(10).unit("ms").help("pause between reconnection attempts"),
            Param::integer("buffers", "16").min(2).max(256).help("stream buffers per camera"),
            Param::integer("packet_size", "0").min(0).unit("bytes")
                .help("GigE Vision stream packet size; 0 = the largest the path carries (Aravis's test packets)"),
            Param::integer("packet_delay_ns", "0").min(0).unit("ns")
                .help("pause between two stream packets (GevSCPD), for links that drop bursts; 0 = none"),
            Param::integer("socket_buffer_bytes", "0").min(0).unit("bytes")
                .help("receive buffer of each stream socket; 0 = room for every stream buffer's image, at most net.core.rmem_max"),
            Param::boolean("packet_resend", true).help("ask the camera to send missing packets again (GigE Vision resend)"),
            Param::boolean("packet_socket", false)
                .help("receive with Aravis's packet socket (less CPU; a camera reopened while others stream may lose frames)"),
            Param::path("calibration", "").help("OpenCV FileStorage YAML calibration published by the source; empty: none"),
        };
    }

    GigeSource(const sdk::CheckedParams &p, sdk::Host &host) : host_(host), notifier_(std::make_shared<Notifier>()) {
        sideBySide_ = p.string("layout") == "side_by_side";
        const PixelFormat *format = findPixelFormat(p.string("pixel_format"));
        if (!format)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "gige: pixel_format = " + p.string("pixel_format") +
                                                          ": not supported (supported: " + supportedPixelFormats() + ")");
        const std::optional<Trigger> trigger = triggerNamed(p.string("trigger"));
        if (!trigger)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "gige: trigger = " + p.string("trigger") + ": expected free_run, software or hardware");
        trigger_ = *trigger;
        toleranceNs_ = static_cast<int64_t>(p.real("pair_tolerance_ms") * 1e6);
        deviceTime_ = p.string("timestamp") == "device";
        if (!p.string("calibration").empty()) calibration_ = readFile(p.string("calibration"));

        CameraSettings base;
        base.format = format;
        // 0 keeps the camera's value (or, for packet_size, lets Aravis choose), set or not.
        auto given = [&](const char *key) { return p.real(key) > 0; };
        if (given("width")) base.width = p.integer("width");
        if (given("height")) base.height = p.integer("height");
        if (given("exposure_us")) base.exposure_us = p.real("exposure_us");
        if (p.isExplicit("gain_db")) base.gain_db = p.real("gain_db");
        if (given("frame_rate_hz")) base.frame_rate_hz = p.real("frame_rate_hz");
        if (given("packet_size")) base.packet_size = p.integer("packet_size");
        base.trigger = trigger_;
        base.trigger_line = p.string("trigger_line");
        base.buffers = static_cast<int>(p.integer("buffers"));
        base.packet_socket = p.boolean("packet_socket");
        base.packet_resend = p.boolean("packet_resend");
        if (given("packet_delay_ns")) base.packet_delay_ns = p.integer("packet_delay_ns");
        base.socket_buffer_bytes = p.integer("socket_buffer_bytes");

        std::vector<CameraSettings> wanted;
        if (sideBySide_) {
            if (p.string("camera").empty())
                throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "gige: layout side_by_side needs 'camera' (device id or IP address; "
                                                          "`binocle devices --plugin gige` lists them)");
            if (base.width && *base.width % 2 != 0)
                throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "gige: width = " + std::to_string(*base.width) +
                                                              ": side_by_side needs an even width (two halves)");
            CameraSettings c = base;
            c.id = p.string("camera");
            c.key = "camera";
            c.role = "left+right";
            wanted.push_back(c);
        } else {
            const std::string l = p.string("camera_left"), r = p.string("camera_right");
            if (l.empty() || r.empty())
                throw Error(BINOCLE_ERR_INVALID_ARGUMENT, std::string("gige: layout two_cameras needs ") +
                                                              (l.empty() ? "camera_left" : "camera_right") +
                                                              " (device id or IP address; `binocle devices --plugin gige` lists them)");
            if (l == r) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "gige: camera_left and camera_right are both '" + l + "'");
            CameraSettings cl = base, cr = base;
            cl.id = l, cl.key = "camera_left", cl.role = "left";
            cr.id = r, cr.key = "camera_right", cr.role = "right";
            wanted = {cl, cr};
        }
        for (const auto &w : wanted) {
            auto slot = std::make_unique<Slot>();
            slot->settings = w;
            slot->camera = std::make_shared<Camera>(w, notifier_);
            slots_.push_back(std::move(slot));
        }
        const Camera &first = *slots_[0]->camera;
        if (sideBySide_ && first.width() % 2 != 0)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "gige: camera " + first.label() + " delivers " + std::to_string(first.width()) +
                                                          " px wide images: side_by_side needs an even width (set width)");
        if (!sideBySide_) {
            const Camera &second = *slots_[1]->camera;
            if (first.width() != second.width() || first.height() != second.height())
                throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "gige: camera " + first.label() + " delivers " + sizeText(first) +
                                                              " images but camera " + second.label() + " delivers " + sizeText(second) +
                                                              ": set width and height");
        }
        width_ = first.width();
        height_ = first.height();
        for (const auto &slot : slots_) warnTransport(*slot->camera);
        if (trigger_ == Trigger::Software)
            for (auto &slot : slots_) slot->trigger = std::make_unique<TriggerWorker>(slot->camera);
        pairing_ = std::make_unique<Pairing>(trigger_, sideBySide_, toleranceNs_, deviceTime_);
        ReconnectionSettings r;
        r.reconnect = reconnect_ = p.boolean("reconnect");
        r.retryInterval = milliseconds(p.integer("retry_interval_ms"));
        r.lostAfter = milliseconds(p.integer("lost_after_ms"));
        r.trigger = trigger_;
        r.width = width_;
        r.height = height_;
        reconnection_ = std::make_unique<Reconnection>(r, slots_, *pairing_, notifier_, host_, running_);
    }

    ~GigeSource() override {
        reconnection_->shutdown(); // closes lost cameras (may wait for Aravis timeouts)
        for (auto &slot : slots_) {
            pairing_->dropPending(*slot, false);
            if (slot->camera) slot->camera->stop();
            slot->camera.reset();
            slot->reconnected.reset(); // the background threads are gone
        }
    }

    void start() override {
        reconnection_->adoptReconnected();
        for (auto &slot : slots_) {
            if (!slot->camera) continue;
            slot->camera->start();
            if (trigger_ == Trigger::FreeRun) slot->awaitingSince = Clock::now();
        }
        running_ = true;
        pairing_->forgetTrigger();
    }

    void stop() override {
        running_ = false;
        for (auto &slot : slots_) {
            pairing_->dropPending(*slot, true); // every image received is accounted for: paired or unpaired
            if (slot->camera) slot->camera->stop();
            slot->awaitingSince.reset();
        }
        pairing_->forgetTrigger();
    }

    std::unique_ptr<sdk::Frame> grab(int32_t timeout_ms) override {
        if (!running_) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "gige: grab before start");
        const Clock::time_point begin = Clock::now();
        const Clock::time_point deadline = timeout_ms < 0 ? Clock::time_point::max() : begin + milliseconds(timeout_ms);
        for (;;) {
            const uint64_t seen = notifier_->events();
            reconnection_->adoptReconnected();
            const Clock::time_point now = Clock::now();

            // Cameras that are gone: a fresh loss is reported at once; while a camera is
            // away, grab waits (within its timeout) for the reconnection.
            std::string fresh = reconnection_->detectLoss(now);
            if (!fresh.empty()) throw Error(BINOCLE_ERR_DEVICE, fresh);
            if (reconnection_->anyDisconnected()) {
                // The cameras still there keep streaming: take their images (they have no
                // partner) so that they count as alive and their buffers go round.
                pairing_->collect(slots_, now);
                for (auto &slot : slots_) pairing_->dropPending(*slot, true);
                if (!reconnect_ || now >= deadline) throw Error(BINOCLE_ERR_DEVICE, reconnection_->disconnectedMessage());
                notifier_->wait(seen, std::min(deadline, now + milliseconds(50)));
                continue;
            }

            if (trigger_ == Trigger::Software && !pairing_->triggerOutstanding()) pairing_->requestTrigger(slots_, now);
            pairing_->collect(slots_, now);
            if (std::optional<Pair> pair = pairing_->next(slots_)) return makeFrame(*pair);
            if (Clock::now() >= deadline) throw Error(BINOCLE_ERR_TIMEOUT, timeoutMessage(timeout_ms));
            // Stream callbacks may fire just before the buffer is queued: look again soon.
            notifier_->wait(seen, std::min(deadline, Clock::now() + milliseconds(5)));
        }
    }

    std::string calibration() override { return calibration_; }

    std::string statistics() override {
        std::ostringstream s;
        s << "live: true\n"; // frames come on the cameras' clock: the host defaults to the latest policy
        s << "layout: " << (sideBySide_ ? "side_by_side" : "two_cameras") << "\n";
        s << "frames: " << sequence_ << "\n";
        s << "unpaired: " << pairing_->unpaired() << "\n";
        s << "reconnections: " << reconnection_->reconnections() << "\n";
        s << "cameras:\n";
        for (const auto &slot : slots_) {
            StreamCounters c = slot->retired;
            if (slot->camera) c += slot->camera->counters();
            s << "  - role: " << slot->settings.role << "\n";
            s << "    device: \"" << slot->settings.id << "\"\n";
            s << "    connected: " << (slot->camera ? "true" : "false") << "\n";
            s << "    images: " << slot->images << "\n";
            s << "    unpaired: " << slot->unpaired << "\n";
            s << "    incomplete_images: " << Pairing::incompleteImages(*slot) << "\n";
            s << "    skipped_frame_ids: " << Pairing::skippedIds(*slot) << "\n";
            s << "    completed_buffers: " << c.completed << "\n";
            s << "    failed_buffers: " << c.failed << "\n";
            s << "    underrun_buffers: " << c.underruns << "\n";
            s << "    missing_packets: " << c.missing_packets << "\n";
            s << "    resent_packets: " << c.resent_packets << "\n";
            if (slot->camera) {
                s << "    packet_size: " << slot->camera->packetSize() << "\n";
                s << "    socket_buffer_bytes: " << slot->camera->socketBufferBytes() << "\n";
            }
            s << "    buffers_lent: " << (slot->camera ? slot->camera->home()->lent() : 0) << "\n";
            s << "    losses: " << slot->losses << "\n";
            if (!slot->failures.empty()) {
                s << "    failed_by_status: {";
                bool firstEntry = true;
                for (const auto &[name, n] : slot->failures) {
                    s << (firstEntry ? "" : ", ") << name << ": " << n;
                    firstEntry = false;
                }
                s << "}\n";
            }
        }
        return s.str();
    }

    static std::string enumerateDevices(sdk::Host &) {
        arv_update_device_list();
        YAML::Emitter out;
        out << YAML::BeginSeq;
        for (unsigned i = 0; i < arv_get_n_devices(); ++i) {
            auto text = [](const char *s) { return std::string(s ? s : ""); };
            const std::string id = text(arv_get_device_id(i)), address = text(arv_get_device_address(i));
            const std::string vendor = text(arv_get_device_vendor(i)), model = text(arv_get_device_model(i));
            const std::string serial = text(arv_get_device_serial_nbr(i)), protocol = text(arv_get_device_protocol(i));
            out << YAML::BeginMap;
            out << YAML::Key << "id" << YAML::Value << id;
            out << YAML::Key << "description" << YAML::Value
                << vendor + " " + model + " (serial " + serial + ")" + (address.empty() ? "" : " at " + address) + ", " + protocol;
            out << YAML::Key << "address" << YAML::Value << address;
            out << YAML::Key << "vendor" << YAML::Value << vendor;
            out << YAML::Key << "model" << YAML::Value << model;
            out << YAML::Key << "serial" << YAML::Value << serial;
            out << YAML::Key << "protocol" << YAML::Value << protocol;
            out << YAML::Key << "physical_id" << YAML::Value << text(arv_get_device_physical_id(i));
            out << YAML::EndMap;
        }
        out << YAML::EndSeq;
        return out.c_str();
    }

private:
    // The kernel silently caps a socket's receive buffer at net.core.rmem_max.
    void warnTransport(const Camera &c) const {
        if (c.socketBufferLimitBytes() > 0 && c.socketBufferBytes() > c.socketBufferLimitBytes())
            host_.warning("gige: camera " + c.label() + ": stream socket buffer of " + std::to_string(c.socketBufferBytes()) +
                          " bytes asked, the kernel grants at most net.core.rmem_max = " + std::to_string(c.socketBufferLimitBytes()) +
                          " bytes; if images lose packets, raise it (sysctl -w net.core.rmem_max=" +
                          std::to_string(c.socketBufferBytes()) + ")");
    }

    std::unique_ptr<sdk::Frame> makeFrame(Pair &pair) {
        std::vector<Pending *> parts;
        for (auto &p : pair.parts) parts.push_back(&p);
        const std::vector<Slot *> &slots = pair.slots;
        struct Pixels {
            cv::Mat converted[2];
        };
        auto pixels = std::make_shared<Pixels>();
        auto frame = std::make_unique<sdk::Frame>();
        frame->sequence = sequence_++;
        std::vector<std::pair<std::shared_ptr<BufferHome>, ArvBuffer *>> lent;
        const Camera &camera0 = *slots[0]->camera;
        const PixelFormat &format = camera0.format();
        std::vector<binocle_image> images;
        for (size_t i = 0; i < parts.size(); ++i) {
            Pending &p = *parts[i];
            const Camera &camera = *slots[i]->camera;
            size_t size = 0;
            void *data = const_cast<void *>(arv_buffer_get_image_data(p.buffer, &size));
            gint xPadding = 0, yPadding = 0;
            arv_buffer_get_image_padding(p.buffer, &xPadding, &yPadding);
            const int stride = camera.width() * format.bytes_per_pixel + xPadding;
            cv::Mat raw(camera.height(), camera.width(), format.bytes_per_pixel == 3 ? CV_8UC3 : CV_8UC1, data, stride);
            binocle_image image{};
            if (format.conversion < 0) {
                image = sdk::makeImage(raw.cols, raw.rows, format.output, raw.data, static_cast<int32_t>(raw.step));
                p.home->lend(p.buffer);
                lent.emplace_back(p.home, p.buffer);
            } else {
                convertPixels(format, raw, pixels->converted[i]);
                p.home->push(p.buffer);
                const cv::Mat &m = pixels->converted[i];
                image = sdk::makeImage(m.cols, m.rows, format.output, m.data, static_cast<int32_t>(m.step));
            }
            images.push_back(image);
            slots[i]->lastSequence = static_cast<int64_t>(frame->sequence);
        }
        std::ostringstream meta;
        if (sideBySide_) {
            // Both halves are views on the one image: no copy either way.
            binocle_image left = images[0], right = images[0];
            const int bpp = sdk::bytesPerPixel(format.output);
            left.width = right.width = images[0].width / 2;
            right.data = static_cast<uint8_t *>(images[0].data) + static_cast<size_t>(left.width) * bpp;
            frame->left = left;
            frame->right = right;
            frame->timestamp_left_ns = frame->timestamp_right_ns = parts[0]->timestamp_ns;
            meta << "camera: \"" << slots[0]->settings.id << "\"\nframe_id: " << parts[0]->frame_id << "\n";
        } else {
            frame->left = images[0];
            frame->right = images[1];
            frame->timestamp_left_ns = parts[0]->timestamp_ns;
            frame->timestamp_right_ns = parts[1]->timestamp_ns;
            meta << "camera_left: \"" << slots[0]->settings.id << "\"\ncamera_right: \"" << slots[1]->settings.id << "\"\n"
                 << "frame_id_left: " << parts[0]->frame_id << "\nframe_id_right: " << parts[1]->frame_id << "\n"
                 << "timestamp_difference_ns: " << (parts[0]->timestamp_ns - parts[1]->timestamp_ns) << "\n";
        }
        meta << "timestamp_source: " << (deviceTime_ ? "device" : "system") << "\n";
        frame->metadata = meta.str();
        frame->owner = pixels;
        if (!lent.empty())
            frame->onRelease = [lent = std::move(lent)] {
                for (const auto &[home, buffer] : lent) home->giveBack(buffer);
            };
        return frame;
    }

    std::string timeoutMessage(int32_t timeout_ms) const {
        std::ostringstream s;
        s << "gige: no " << (sideBySide_ ? "image" : "stereo pair") << " within " << timeout_ms << " ms (";
        for (size_t i = 0; i < slots_.size(); ++i) {
            const Slot &slot = *slots_[i];
            s << (i ? "; " : "") << slot.settings.role << ": " << slot.pending.size() << " image(s) waiting";
            for (const auto &[name, n] : slot.failures) s << ", " << n << " failed buffer(s) " << name;
        }
        if (trigger_ == Trigger::Hardware) s << "; waiting for hardware triggers on " << slots_[0]->settings.trigger_line;
        if (pairing_->unpaired() > 0)
            s << "; " << pairing_->unpaired() << " image(s) left unpaired so far, last left/right time stamps "
              << formatMs(std::abs(static_cast<double>(pairing_->lastUnpairedDtNs())) / 1e6) << " ms apart, pair_tolerance_ms "
              << formatMs(static_cast<double>(toleranceNs_) / 1e6);
        s << ")";
        return s.str();
    }

    sdk::Host host_;
    std::shared_ptr<Notifier> notifier_;
    Slots slots_; // [left, right] or [the side-by-side camera]
    bool sideBySide_ = false;
    Trigger trigger_ = Trigger::FreeRun;
    int64_t toleranceNs_ = 0;
    bool deviceTime_ = false;
    bool reconnect_ = true;
    std::string calibration_;
    int width_ = 0, height_ = 0;
    std::atomic<bool> running_{false};
    uint64_t sequence_ = 0;
    std::unique_ptr<Pairing> pairing_;
    std::unique_ptr<Reconnection> reconnection_;
};

} // namespace binocle::gige

BINOCLE_EXPORT_SOURCE(binocle::gige::GigeSource, "gige", "1.0.0",
                      "GigE Vision stereo rig through Aravis: two cameras or one side-by-side camera")
