// SPDX-License-Identifier: MIT
// The `gige` StereoSource: a stereo rig of two GigE Vision cameras, or one camera that
// delivers both images side by side, through Aravis 0.8. Pairs are formed by time stamp;
// a camera that stops answering is reported and reconnected in the background, and no
// wait lasts longer than grab's timeout. Settings and behaviour: README.md beside this file.
#include "gige_camera.hpp"
#include "pixel_formats.hpp"

#include "common/param_check.hpp"

#include <binocle/plugin.hpp>
#include <opencv2/core.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>
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

double msBetween(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

const char *statusName(ArvBufferStatus s) {
    switch (s) {
    case ARV_BUFFER_STATUS_SUCCESS: return "success";
    case ARV_BUFFER_STATUS_CLEARED: return "cleared";
    case ARV_BUFFER_STATUS_TIMEOUT: return "timeout";
    case ARV_BUFFER_STATUS_MISSING_PACKETS: return "missing_packets";
    case ARV_BUFFER_STATUS_WRONG_PACKET_ID: return "wrong_packet_id";
    case ARV_BUFFER_STATUS_SIZE_MISMATCH: return "size_mismatch";
    case ARV_BUFFER_STATUS_FILLING: return "filling";
    case ARV_BUFFER_STATUS_ABORTED: return "aborted";
    default: return "unknown";
    }
}

// A buffer taken from a stream, waiting for its partner.
struct Pending {
    ArvBuffer *buffer = nullptr;
    std::shared_ptr<BufferHome> home;
    int64_t timestamp_ns = 0;
    uint64_t frame_id = 0;
};

// Sends one camera's software triggers from a thread of its own: a camera that is gone
// takes seconds to fail, and must delay neither grab nor the other camera's trigger.
class TriggerWorker {
public:
    explicit TriggerWorker(std::shared_ptr<Camera> camera) : camera_(std::move(camera)) {
        thread_ = std::thread([this] { loop(); });
    }
    ~TriggerWorker() { // waits for a trigger in flight (bounded by Aravis's timeouts)
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
        }
        cv_.notify_all();
        thread_.join();
    }
    void request() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            pending_ = true;
        }
        cv_.notify_all();
    }

private:
    void loop() {
        std::unique_lock<std::mutex> lock(mutex_);
        for (;;) {
            cv_.wait(lock, [&] { return stop_ || pending_; });
            if (stop_) return;
            pending_ = false;
            lock.unlock();
            try {
                camera_->softwareTrigger();
            } catch (const std::exception &e) {
                camera_->markLost(std::string("software trigger unanswered: ") + e.what());
            }
            lock.lock();
        }
    }
    std::shared_ptr<Camera> camera_;
    std::mutex mutex_;
    std::condition_variable cv_;
    bool stop_ = false, pending_ = false;
    std::thread thread_;
};

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

    GigeSource(const sdk::Params &p, sdk::Host &host) : host_(host), notifier_(std::make_shared<Notifier>()) {
        plugins::checkParameters(p, parameters(), "gige");
        sideBySide_ = p.string("layout") == "side_by_side";
        const PixelFormat *format = findPixelFormat(p.string("pixel_format"));
        if (!format)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "gige: pixel_format = " + p.string("pixel_format") +
                                                          ": not supported (supported: " + supportedPixelFormats() + ")");
        trigger_ = p.string("trigger");
        toleranceNs_ = static_cast<int64_t>(p.real("pair_tolerance_ms") * 1e6);
        deviceTime_ = p.string("timestamp") == "device";
        lostAfter_ = milliseconds(p.integer("lost_after_ms"));
        reconnect_ = p.boolean("reconnect");
        retryInterval_ = milliseconds(p.integer("retry_interval_ms"));
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
        if (trigger_ == "software")
            for (auto &slot : slots_) slot->trigger = std::make_unique<TriggerWorker>(slot->camera);
    }

    ~GigeSource() override {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            closing_ = true;
        }
        wake_.notify_all();
        for (auto &slot : slots_) slot->trigger.reset();
        for (auto &t : background_) t.join(); // closes lost cameras (may wait for Aravis timeouts)
        for (auto &slot : slots_) {
            dropPending(*slot, false);
            if (slot->camera) slot->camera->stop();
            slot->camera.reset();
            std::lock_guard<std::mutex> lock(mutex_);
            slot->reconnected.reset();
        }
    }

    void start() override {
        adoptReconnected();
        for (auto &slot : slots_) {
            if (!slot->camera) continue;
            slot->camera->start();
            if (trigger_ == "free_run") slot->awaitingSince = Clock::now();
        }
        running_ = true;
        triggerOutstanding_ = false;
    }

    void stop() override {
        running_ = false;
        for (auto &slot : slots_) {
            dropPending(*slot, true); // every image received is accounted for: paired or unpaired
            if (slot->camera) slot->camera->stop();
            slot->awaitingSince.reset();
        }
        triggerOutstanding_ = false;
    }

    std::unique_ptr<sdk::Frame> grab(int32_t timeout_ms) override {
        if (!running_) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "gige: grab before start");
        const Clock::time_point begin = Clock::now();
        const Clock::time_point deadline = timeout_ms < 0 ? Clock::time_point::max() : begin + milliseconds(timeout_ms);
        for (;;) {
            const uint64_t seen = notifier_->events();
            adoptReconnected();
            const Clock::time_point now = Clock::now();

            // Cameras that are gone: a fresh loss is reported at once; while a camera is
            // away, grab waits (within its timeout) for the reconnection.
            std::string fresh = detectLoss(now);
            if (!fresh.empty()) throw Error(BINOCLE_ERR_DEVICE, fresh);
            if (anyDisconnected()) {
                // The cameras still there keep streaming: take their images (they have no
                // partner) so that they count as alive and their buffers go round.
                collect(now);
                for (auto &slot : slots_) dropPending(*slot, true);
                if (!reconnect_ || now >= deadline) throw Error(BINOCLE_ERR_DEVICE, disconnectedMessage());
                notifier_->wait(seen, std::min(deadline, now + milliseconds(50)));
                continue;
            }

            if (trigger_ == "software" && !triggerOutstanding_) requestTrigger(now);
            collect(now);
            if (auto frame = pair()) return frame;
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
        s << "unpaired: " << unpaired_ << "\n";
        s << "reconnections: " << reconnections_ << "\n";
        s << "cameras:\n";
        for (const auto &slot : slots_) {
            StreamCounters c = slot->retired;
            if (slot->camera) c += slot->camera->counters();
            s << "  - role: " << slot->settings.role << "\n";
            s << "    device: \"" << slot->settings.id << "\"\n";
            s << "    connected: " << (slot->camera ? "true" : "false") << "\n";
            s << "    images: " << slot->images << "\n";
            s << "    unpaired: " << slot->unpaired << "\n";
            s << "    incomplete_images: " << incompleteImages(*slot) << "\n";
            s << "    skipped_frame_ids: " << skippedIds(*slot) << "\n";
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
    struct Slot {
        CameraSettings settings;
        std::shared_ptr<Camera> camera;    // null while the camera is away
        std::shared_ptr<Camera> reconnected; // set by the background thread (mutex_)
        std::deque<Pending> pending;
        std::optional<Clock::time_point> awaitingSince; // an image is due since then
        int64_t lastSequence = -1;                      // last frame this camera took part in
        std::string lostWhy;                            // why it is away
        int attempts = 0;                               // reconnection attempts (mutex_)
        std::string lastAttemptError;                   // (mutex_)
        StreamCounters retired;                         // counters of closed streams
        uint64_t images = 0, losses = 0, unpaired = 0, idGap = 0;
        std::optional<uint64_t> lastFrameId; // of the current camera
        std::map<std::string, uint64_t> failures;
        std::unique_ptr<TriggerWorker> trigger; // software trigger: of the current camera
        bool answered = false;                  // software trigger: an image came for the last one
    };

    // The kernel silently caps a socket's receive buffer at net.core.rmem_max.
    void warnTransport(const Camera &c) const {
        if (c.socketBufferLimitBytes() > 0 && c.socketBufferBytes() > c.socketBufferLimitBytes())
            host_.warning("gige: camera " + c.label() + ": stream socket buffer of " + std::to_string(c.socketBufferBytes()) +
                          " bytes asked, the kernel grants at most net.core.rmem_max = " + std::to_string(c.socketBufferLimitBytes()) +
                          " bytes; if images lose packets, raise it (sysctl -w net.core.rmem_max=" +
                          std::to_string(c.socketBufferBytes()) + ")");
    }

    static std::string sizeText(const Camera &c) {
        return std::to_string(c.width()) + "x" + std::to_string(c.height()) + " " + c.format().name;
    }

    std::string afterFrame(const Slot &slot) const {
        return slot.lastSequence < 0 ? "before the first frame" : "after frame " + std::to_string(slot.lastSequence);
    }

    bool anyDisconnected() const {
        for (const auto &slot : slots_)
            if (!slot->camera) return true;
        return false;
    }

    void noteUnpaired(Slot &slot) {
        ++unpaired_;
        ++slot.unpaired;
    }

    // Frame ids between two complete images, not counted otherwise: the camera numbered
    // them but they never left the stream (every packet lost, or no free buffer). Only
    // complete images' ids are trusted: a buffer that lost packets may carry any id.
    // GVSP 1.x ids run 1..65535, then wrap.
    static void countIdGap(Slot &slot, uint64_t id) {
        if (id == 0) return;
        if (slot.lastFrameId) {
            const uint64_t last = *slot.lastFrameId;
            if (id > last) slot.idGap += id - last - 1;
            else if (last - id > 32768 && last <= 65535) slot.idGap += (65535 - last) + (id - 1);
            else return; // an older image given up late, or a repeat: nothing skipped, `last` stays
        }
        slot.lastFrameId = id;
    }

    static uint64_t incompleteImages(const Slot &slot) {
        uint64_t n = 0;
        for (const auto &[name, count] : slot.failures) n += count;
        return n;
    }

    // Ids skipped between complete images, less the incomplete images among them.
    static uint64_t skippedIds(const Slot &slot) {
        const uint64_t incomplete = incompleteImages(slot);
        return slot.idGap > incomplete ? slot.idGap - incomplete : 0;
    }

    void dropPending(Slot &slot, bool countUnpaired) {
        for (auto &p : slot.pending) {
            p.home->push(p.buffer);
            if (countUnpaired) noteUnpaired(slot);
        }
        slot.pending.clear();
    }

    // Finds cameras that went away since the last look; hands each to a background thread
    // (closing it waits for Aravis timeouts) and returns the message to report, or "".
    std::string detectLoss(Clock::time_point now) {
        std::string message;
        for (auto &slotPtr : slots_) {
            Slot &slot = *slotPtr;
            if (!slot.camera) continue;
            std::string why = slot.camera->lostReason();
            if (why.empty() && slot.awaitingSince && now - *slot.awaitingSince > lostAfter_)
                why = "no image for " + formatMs(msBetween(*slot.awaitingSince, now)) + " ms";
            if (why.empty()) continue;
            slot.lostWhy = why;
            slot.camera->markLost(why); // from now on nothing talks to it
            ++slot.losses;
            slot.retired += slot.camera->counters();
            const std::string label = slot.camera->label();
            loseCamera(slot);
            message += (message.empty() ? "gige: " : "; ") + std::string("camera ") + label + " stopped answering " +
                       afterFrame(slot) + " (" + why + ")";
        }
        if (message.empty()) return message;
        for (auto &slot : slots_) {
            dropPending(*slot, true);
            // No trigger goes out while a camera is away: the others owe no image.
            if (trigger_ == "software") slot->awaitingSince.reset();
        }
        triggerOutstanding_ = false;
        return message + (reconnect_ ? "; reconnecting every " + std::to_string(retryInterval_.count()) + " ms" : "; reconnect is off");
    }

    void loseCamera(Slot &slot) {
        dropPending(slot, false);
        std::shared_ptr<Camera> dead = std::move(slot.camera);
        slot.awaitingSince.reset();
        Slot *s = &slot;
        std::lock_guard<std::mutex> lock(mutex_);
        s->attempts = 0;
        s->lastAttemptError.clear();
        // Closing a camera that is gone waits for control-channel timeouts (its trigger
        // thread too, when a trigger is in flight): never in grab.
        background_.emplace_back([dead = std::move(dead), trigger = std::move(s->trigger)]() mutable {
            trigger.reset();
            dead.reset();
        });
        if (reconnect_) background_.emplace_back([this, s] { reconnectLoop(*s); });
    }

    void reconnectLoop(Slot &slot) {
        std::unique_lock<std::mutex> lock(mutex_);
        while (!closing_) {
            wake_.wait_for(lock, retryInterval_, [&] { return closing_; });
            if (closing_) return;
            ++slot.attempts;
            const CameraSettings settings = slot.settings;
            lock.unlock();
            std::shared_ptr<Camera> camera;
            std::string error;
            try {
                camera = std::make_shared<Camera>(settings, notifier_, false);
                if (camera->width() != width_ || camera->height() != height_)
                    throw Error(BINOCLE_ERR_DEVICE, "gige: camera " + camera->label() + " is back with " + sizeText(*camera) +
                                                        " images instead of " + std::to_string(width_) + "x" + std::to_string(height_));
                if (running_) camera->start();
            } catch (const std::exception &e) {
                error = e.what();
                camera.reset();
            }
            lock.lock();
            if (camera) {
                slot.reconnected = std::move(camera);
                lock.unlock();
                notifier_->notify();
                return;
            }
            slot.lastAttemptError = error;
        }
    }

    // Takes in cameras the background threads have reopened.
    void adoptReconnected() {
        bool any = false;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            for (auto &slot : slots_) {
                if (!slot->reconnected) continue;
                slot->camera = std::move(slot->reconnected);
                slot->lastFrameId.reset(); // a reopened camera numbers its frames anew
                if (trigger_ == "software") slot->trigger = std::make_unique<TriggerWorker>(slot->camera);
                host_.info("gige: camera " + slot->camera->label() + " is back (" + std::to_string(slot->attempts) +
                           " attempt(s)); streaming again");
                ++reconnections_;
                any = true;
            }
        }
        if (!any) return;
        const Clock::time_point now = Clock::now();
        for (auto &slot : slots_) {
            dropPending(*slot, true);
            if (!slot->camera) continue;
            if (running_ && !slot->camera->acquiring()) slot->camera->start(); // start() raced the reopening
            if (!running_) slot->camera->stop();
            if (running_ && trigger_ == "free_run") slot->awaitingSince = now;
        }
        triggerOutstanding_ = false;
    }

    std::string disconnectedMessage() {
        std::string message;
        std::lock_guard<std::mutex> lock(mutex_);
        for (const auto &slot : slots_) {
            if (slot->camera) continue;
            message += (message.empty() ? "gige: " : "; ") + std::string("camera ") + slot->settings.id + " (" + slot->settings.role +
                       ") is disconnected since " +
                       (slot->lastSequence < 0 ? std::string("the start") : "frame " + std::to_string(slot->lastSequence)) + " (" +
                       slot->lostWhy + ")";
            if (reconnect_)
                message += "; reconnecting every " + std::to_string(retryInterval_.count()) + " ms, " + std::to_string(slot->attempts) +
                           " attempt(s)" + (slot->lastAttemptError.empty() ? "" : ", last: " + slot->lastAttemptError);
            else
                message += "; reconnect is off";
        }
        return message;
    }

    void requestTrigger(Clock::time_point now) {
        for (auto &slot : slots_) {
            dropPending(*slot, true);
            slot->answered = false;
            slot->trigger->request();
            if (!slot->awaitingSince) slot->awaitingSince = now;
        }
        triggerOutstanding_ = true;
    }

    // Takes every finished buffer out of the streams.
    void collect(Clock::time_point now) {
        for (auto &slotPtr : slots_) {
            Slot &slot = *slotPtr;
            if (!slot.camera) continue;
            Camera &camera = *slot.camera;
            while (ArvBuffer *buffer = camera.tryPop()) {
                const ArvBufferStatus status = arv_buffer_get_status(buffer);
                if (trigger_ == "software") {
                    // Exactly one image per camera answers a trigger: anything more is stale.
                    if (slot.answered) {
                        camera.home()->push(buffer);
                        if (status == ARV_BUFFER_STATUS_SUCCESS) noteUnpaired(slot);
                        continue;
                    }
                    slot.answered = true;
                    slot.awaitingSince.reset();
                } else if (trigger_ == "free_run") {
                    slot.awaitingSince = now;
                }
                if (status == ARV_BUFFER_STATUS_SUCCESS) countIdGap(slot, arv_buffer_get_frame_id(buffer));
                if (status != ARV_BUFFER_STATUS_SUCCESS) {
                    ++slot.failures[statusName(status)];
                    camera.home()->push(buffer);
                    continue;
                }
                try {
                    checkImage(camera, buffer);
                } catch (...) {
                    if (trigger_ == "software") triggerOutstanding_ = false;
                    throw;
                }
                Pending p;
                p.buffer = buffer;
                p.home = camera.home();
                p.timestamp_ns = static_cast<int64_t>(deviceTime_ ? arv_buffer_get_timestamp(buffer) : arv_buffer_get_system_timestamp(buffer));
                p.frame_id = arv_buffer_get_frame_id(buffer);
                slot.pending.push_back(std::move(p));
                ++slot.images;
                // A partner that never comes must not hold every buffer of the stream.
                const size_t keep = std::max<size_t>(1, static_cast<size_t>(slot.settings.buffers / 2));
                while (slot.pending.size() > keep) {
                    slot.pending.front().home->push(slot.pending.front().buffer);
                    slot.pending.pop_front();
                    noteUnpaired(slot);
                }
            }
        }
    }

    // Refuses a buffer that does not hold the image the camera was configured for.
    void checkImage(Camera &camera, ArvBuffer *buffer) {
        const int w = arv_buffer_get_image_width(buffer), h = arv_buffer_get_image_height(buffer);
        const ArvPixelFormat pf = arv_buffer_get_image_pixel_format(buffer);
        size_t size = 0;
        arv_buffer_get_image_data(buffer, &size);
        gint xPadding = 0, yPadding = 0;
        arv_buffer_get_image_padding(buffer, &xPadding, &yPadding);
        const PixelFormat &f = camera.format();
        const size_t needed = (static_cast<size_t>(w) * f.bytes_per_pixel + xPadding) * h;
        if (w == camera.width() && h == camera.height() && pf == f.arv && size >= needed) return;
        const PixelFormat *got = findPixelFormat(pf);
        std::ostringstream what;
        what << "gige: camera " << camera.label() << " sent a " << w << "x" << h << " "
             << (got ? got->name : ("pixel format 0x" + [&] { std::ostringstream x; x << std::hex << pf; return x.str(); }()))
             << " image of " << size << " bytes; expected " << camera.width() << "x" << camera.height() << " " << f.name
             << " (wrong frame size: was the camera reconfigured behind this source's back?)";
        camera.home()->push(buffer);
        throw Error(BINOCLE_ERR_DEVICE, what.str());
    }

    std::unique_ptr<sdk::Frame> pair() {
        if (trigger_ == "software") return pairTriggered();
        if (sideBySide_) {
            Slot &slot = *slots_[0];
            if (slot.pending.empty()) return nullptr;
            Pending p = std::move(slot.pending.front());
            slot.pending.pop_front();
            return makeFrame({&p}, {&slot});
        }
        Slot &l = *slots_[0], &r = *slots_[1];
        while (!l.pending.empty() && !r.pending.empty()) {
            const int64_t dt = l.pending.front().timestamp_ns - r.pending.front().timestamp_ns;
            if (std::llabs(dt) <= toleranceNs_) {
                Pending a = std::move(l.pending.front()), b = std::move(r.pending.front());
                l.pending.pop_front();
                r.pending.pop_front();
                return makeFrame({&a, &b}, {&l, &r});
            }
            lastUnpairedDtNs_ = dt;
            Slot &older = dt < 0 ? l : r;
            older.pending.front().home->push(older.pending.front().buffer);
            older.pending.pop_front();
            noteUnpaired(older);
        }
        return nullptr;
    }

    // Software trigger: the images that answer one trigger make the pair, once every camera
    // has answered; a failed image (or time stamps too far apart) drops the others and the
    // next call triggers again. Time stamps alone could pair images of two triggers sent
    // within pair_tolerance_ms.
    std::unique_ptr<sdk::Frame> pairTriggered() {
        for (const auto &slot : slots_)
            if (!slot->answered) return nullptr;
        triggerOutstanding_ = false;
        bool complete = true;
        for (const auto &slot : slots_) complete = complete && slot->pending.size() == 1;
        if (complete && !sideBySide_) {
            const int64_t dt = slots_[0]->pending.front().timestamp_ns - slots_[1]->pending.front().timestamp_ns;
            if (std::llabs(dt) > toleranceNs_) {
                lastUnpairedDtNs_ = dt;
                complete = false;
            }
        }
        if (!complete) {
            for (auto &slot : slots_) dropPending(*slot, true);
            return nullptr;
        }
        std::vector<Pending> parts;
        std::vector<Slot *> owners;
        for (auto &slot : slots_) {
            parts.push_back(std::move(slot->pending.front()));
            slot->pending.clear();
            owners.push_back(slot.get());
        }
        std::vector<Pending *> views;
        for (auto &p : parts) views.push_back(&p);
        return makeFrame(views, owners);
    }

    std::unique_ptr<sdk::Frame> makeFrame(const std::vector<Pending *> &parts, const std::vector<Slot *> &slots) {
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
        if (trigger_ == "software") triggerOutstanding_ = false;
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
        if (trigger_ == "hardware") s << "; waiting for hardware triggers on " << slots_[0]->settings.trigger_line;
        if (unpaired_ > 0)
            s << "; " << unpaired_ << " image(s) left unpaired so far, last left/right time stamps "
              << formatMs(std::abs(static_cast<double>(lastUnpairedDtNs_)) / 1e6) << " ms apart, pair_tolerance_ms "
              << formatMs(static_cast<double>(toleranceNs_) / 1e6);
        s << ")";
        return s.str();
    }

    sdk::Host host_;
    std::shared_ptr<Notifier> notifier_;
    std::vector<std::unique_ptr<Slot>> slots_; // [left, right] or [the side-by-side camera]
    bool sideBySide_ = false;
    std::string trigger_;
    int64_t toleranceNs_ = 0;
    bool deviceTime_ = false;
    milliseconds lostAfter_{1000};
    bool reconnect_ = true;
    milliseconds retryInterval_{1000};
    std::string calibration_;
    int width_ = 0, height_ = 0;

    std::atomic<bool> running_{false};
    bool triggerOutstanding_ = false;
    uint64_t sequence_ = 0, unpaired_ = 0, reconnections_ = 0;
    int64_t lastUnpairedDtNs_ = 0;

    // Shared with the background threads.
    std::mutex mutex_;
    std::condition_variable wake_;
    bool closing_ = false;
    std::vector<std::thread> background_;
};

} // namespace binocle::gige

BINOCLE_EXPORT_SOURCE(binocle::gige::GigeSource, "gige", "1.0.0",
                      "GigE Vision stereo rig through Aravis: two cameras or one side-by-side camera")
