// SPDX-License-Identifier: MIT
// One GigE Vision camera through Aravis: opened by device id or IP address, configured
// from the rig's settings, streaming into buffers that the source lends without copying.
#include "gige_camera.hpp"

#include <binocle/plugin.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <vector>

namespace binocle::gige {

namespace {

// An owned GError, for the GError ** out-parameters of Aravis.
class GErrorSlot {
public:
    ~GErrorSlot() { clear(); }
    GError **out() {
        clear();
        return &error_;
    }
    explicit operator bool() const { return error_ != nullptr; }
    std::string message() const { return error_ && error_->message ? error_->message : "unknown error"; }

private:
    void clear() {
        if (error_) g_error_free(error_);
        error_ = nullptr;
    }
    GError *error_ = nullptr;
};

std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

std::string joinStrings(const char **items, guint n) {
    std::string all;
    for (guint i = 0; i < n; ++i)
        if (items[i]) all += (all.empty() ? "" : ", ") + std::string(items[i]);
    return all.empty() ? "none" : all;
}

} // namespace

std::optional<Trigger> triggerNamed(const std::string &name) {
    if (name == "free_run") return Trigger::FreeRun;
    if (name == "software") return Trigger::Software;
    if (name == "hardware") return Trigger::Hardware;
    return std::nullopt;
}

// ---- Notifier -------------------------------------------------------------------------

void Notifier::notify() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        ++events_;
    }
    cv_.notify_all();
}

uint64_t Notifier::events() {
    std::lock_guard<std::mutex> lock(mutex_);
    return events_;
}

void Notifier::wait(uint64_t seen, Clock::time_point until) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_until(lock, until, [&] { return events_ != seen; });
}

// ---- BufferHome -----------------------------------------------------------------------

BufferHome::BufferHome(ArvStream *stream) : stream_(stream) { g_object_ref(stream_); }

BufferHome::~BufferHome() {
    if (stream_) g_object_unref(stream_);
}

void BufferHome::lend(ArvBuffer *) { ++lent_; }

void BufferHome::giveBack(ArvBuffer *buffer) {
    --lent_;
    push(buffer);
}

void BufferHome::push(ArvBuffer *buffer) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stream_) arv_stream_push_buffer(stream_, buffer);
    else g_object_unref(buffer);
}

ArvStream *BufferHome::retire() {
    std::lock_guard<std::mutex> lock(mutex_);
    ArvStream *s = stream_;
    stream_ = nullptr;
    return s;
}

StreamCounters &StreamCounters::operator+=(const StreamCounters &o) {
    completed += o.completed;
    failed += o.failed;
    underruns += o.underruns;
    missing_packets += o.missing_packets;
    resent_packets += o.resent_packets;
    return *this;
}

// ---- Camera ---------------------------------------------------------------------------

std::string Camera::listDevices() {
    arv_update_device_list();
    std::string all;
    for (unsigned i = 0; i < arv_get_n_devices(); ++i) {
        const char *id = arv_get_device_id(i);
        const char *address = arv_get_device_address(i);
        all += (all.empty() ? "" : ", ") + std::string(id ? id : "?") + (address && *address ? " (" + std::string(address) + ")" : "");
    }
    return all.empty() ? "none" : all;
}

Camera::Camera(const CameraSettings &settings, std::shared_ptr<Notifier> notifier, bool listOnFailure)
    : settings_(settings), notifier_(std::move(notifier)), lost_(std::make_shared<LostState>()) {
    lost_->notifier = notifier_;
    GErrorSlot error;
    camera_ = arv_camera_new(settings_.id.c_str(), error.out());
    if (!camera_) {
        std::string msg = "gige: " + settings_.key + " = '" + settings_.id +
                          "': no camera answers to this device id or IP address (Aravis: " + error.message() + ")";
        if (listOnFailure) msg += "; cameras found: " + listDevices() + " (see `binocle devices --plugin gige`)";
        throw sdk::Error(BINOCLE_ERR_NOT_FOUND, msg);
    }
    try {
        configure();
    } catch (...) {
        if (home_) stream_ = home_->retire();
        home_.reset();
        if (stream_) g_object_unref(stream_);
        if (controlLostHandler_) g_signal_handler_disconnect(arv_camera_get_device(camera_), controlLostHandler_);
        g_object_unref(camera_);
        throw;
    }
}

Camera::~Camera() {
    if (acquiring_ && lostReason().empty()) arv_camera_stop_acquisition(camera_, nullptr);
    if (controlLostHandler_) g_signal_handler_disconnect(arv_camera_get_device(camera_), controlLostHandler_);
    // Buffers still lent are freed when they come back; those queued go with the stream.
    if (home_) {
        if (ArvStream *s = home_->retire()) g_object_unref(s);
    }
    g_object_unref(camera_);
}

void Camera::fail(int32_t code, const std::string &what) const {
    throw sdk::Error(code, "gige: camera " + label_ + ": " + what);
}

void Camera::configure() {
    identify();
    GErrorSlot error;
    // A camera left acquiring by an earlier session refuses some settings.
    arv_camera_stop_acquisition(camera_, error.out());
    arv_camera_set_acquisition_mode(camera_, ARV_ACQUISITION_MODE_CONTINUOUS, error.out());
    configurePixelFormat();
    configureImageSize();
    configureExposureGainRate();
    configureTrigger();
    if (arv_camera_is_gv_device(camera_)) configureTransport();
    openStream();
}

// Its address and label; refuses a camera another controller holds.
void Camera::identify() {
    ArvDevice *device = arv_camera_get_device(camera_);
    address_ = settings_.id;
    if (arv_camera_is_gv_device(camera_)) {
        GSocketAddress *a = arv_gv_device_get_device_address(ARV_GV_DEVICE(device));
        if (a && G_IS_INET_SOCKET_ADDRESS(a)) {
            gchar *text = g_inet_address_to_string(g_inet_socket_address_get_address(G_INET_SOCKET_ADDRESS(a)));
            if (text) address_ = text;
            g_free(text);
        }
    }
    label_ = settings_.id + (address_ != settings_.id ? " at " + address_ : "") + " (" + settings_.role + ")";
    // Aravis opens a camera that another controller holds read-only; every write would then
    // time out, one after the other.
    if (ARV_IS_GV_DEVICE(device) && !arv_gv_device_is_controller(ARV_GV_DEVICE(device)))
        fail(BINOCLE_ERR_BUSY, "another application (or another source) controls it; close that first");
}

// Pixel format: compared by PFNC value, so "RGB8" and "RGB8Packed" name the same.
void Camera::configurePixelFormat() {
    GErrorSlot error;
    const PixelFormat &format = *settings_.format;
    {
        guint n = 0, nNames = 0;
        gint64 *values = arv_camera_dup_available_pixel_formats(camera_, &n, error.out());
        const char **names = arv_camera_dup_available_pixel_formats_as_strings(camera_, &nNames, nullptr);
        bool offered = false;
        for (guint i = 0; values && i < n; ++i) offered = offered || values[i] == static_cast<gint64>(format.arv);
        const std::string all = names ? joinStrings(names, nNames) : "none";
        g_free(values);
        g_free(names);
        if (!offered)
            fail(BINOCLE_ERR_UNSUPPORTED, "pixel_format = " + std::string(format.name) + " not offered (the camera offers: " + all + ")");
        arv_camera_set_pixel_format(camera_, format.arv, error.out());
        if (error) fail(BINOCLE_ERR_DEVICE, "pixel_format = " + std::string(format.name) + " refused: " + error.message());
    }
}

// Width and Height: Aravis's bounds know the sensor size (the features' own maximum
// may be unbounded).
void Camera::configureImageSize() {
    GErrorSlot error;
    using Bounds = void (*)(ArvCamera *, gint *, gint *, GError **);
    using Increment = gint (*)(ArvCamera *, GError **);
    auto setDimension = [&](const char *feature, const char *key, const char *offset, int64_t value, Bounds bounds,
                            Increment increment) {
        if (arv_camera_is_feature_available(camera_, offset, nullptr)) arv_camera_set_integer(camera_, offset, 0, error.out());
        gint lo = 0, hi = 0;
        bounds(camera_, &lo, &hi, error.out());
        int64_t step = increment(camera_, error.out());
        if (step < 1) step = 1;
        const std::string given = std::string(key) + " = " + std::to_string(value);
        const std::string accepted = "the camera takes " + std::to_string(lo) + ".." + std::to_string(hi) +
                                     (step > 1 ? " in steps of " + std::to_string(step) : "");
        if (value < lo || value > hi || (value - lo) % step != 0) fail(BINOCLE_ERR_INVALID_ARGUMENT, given + " not accepted (" + accepted + ")");
        arv_camera_set_integer(camera_, feature, value, error.out());
        if (error) fail(BINOCLE_ERR_INVALID_ARGUMENT, given + " refused: " + error.message());
        const gint64 now = arv_camera_get_integer(camera_, feature, error.out());
        if (now != value)
            fail(BINOCLE_ERR_INVALID_ARGUMENT, given + " not accepted (the camera set " + std::to_string(now) + "; " + accepted + ")");
    };
    if (settings_.width)
        setDimension("Width", "width", "OffsetX", *settings_.width, arv_camera_get_width_bounds, arv_camera_get_width_increment);
    if (settings_.height)
        setDimension("Height", "height", "OffsetY", *settings_.height, arv_camera_get_height_bounds, arv_camera_get_height_increment);
}

// Float features: switch the automatic off, check the camera's range, set.
void Camera::configureExposureGainRate() {
    GErrorSlot error;
    struct FloatFeature {
        const char *key, *unit, *what;
        const std::optional<double> &value;
        gboolean (*available)(ArvCamera *, GError **);
        gboolean (*autoAvailable)(ArvCamera *, GError **); // nullptr: no automatic
        void (*setAuto)(ArvCamera *, ArvAuto, GError **);
        void (*bounds)(ArvCamera *, double *, double *, GError **);
        void (*set)(ArvCamera *, double, GError **);
    };
    const FloatFeature features[] = {
        {"exposure_us", "us", "exposure", settings_.exposure_us, arv_camera_is_exposure_time_available,
         arv_camera_is_exposure_auto_available, arv_camera_set_exposure_time_auto, arv_camera_get_exposure_time_bounds,
         arv_camera_set_exposure_time},
        {"gain_db", "dB", "gain", settings_.gain_db, arv_camera_is_gain_available, arv_camera_is_gain_auto_available,
         arv_camera_set_gain_auto, arv_camera_get_gain_bounds, arv_camera_set_gain},
        {"frame_rate_hz", "Hz", "frame rate", settings_.frame_rate_hz, arv_camera_is_frame_rate_available, nullptr, nullptr,
         arv_camera_get_frame_rate_bounds, arv_camera_set_frame_rate},
    };
    for (const FloatFeature &f : features) {
        if (!f.value) continue;
        const std::string given = std::string(f.key) + " = " + number(*f.value);
        if (!f.available(camera_, nullptr)) fail(BINOCLE_ERR_UNSUPPORTED, given + ": the camera has no " + f.what + " control");
        if (f.autoAvailable && f.autoAvailable(camera_, nullptr)) f.setAuto(camera_, ARV_AUTO_OFF, error.out());
        double lo = 0, hi = 0;
        f.bounds(camera_, &lo, &hi, error.out());
        if (*f.value < lo || *f.value > hi)
            fail(BINOCLE_ERR_INVALID_ARGUMENT, given + " not accepted (the camera takes " + number(lo) + ".." + number(hi) + " " + f.unit + ")");
        f.set(camera_, *f.value, error.out());
        if (error) fail(BINOCLE_ERR_INVALID_ARGUMENT, given + " refused: " + error.message());
    }
}

void Camera::configureTrigger() {
    GErrorSlot error;
    switch (settings_.trigger) {
    case Trigger::FreeRun: arv_camera_clear_triggers(camera_, error.out()); break;
    case Trigger::Software:
        if (!arv_camera_is_software_trigger_supported(camera_, nullptr))
            fail(BINOCLE_ERR_UNSUPPORTED, "trigger = software: the camera has no software trigger");
        arv_camera_set_trigger(camera_, "Software", error.out());
        if (error) fail(BINOCLE_ERR_DEVICE, "trigger = software refused: " + error.message());
        break;
    case Trigger::Hardware: {
        guint n = 0;
        const char **sources = arv_camera_dup_available_trigger_sources(camera_, &n, error.out());
        bool found = false;
        for (guint i = 0; sources && i < n; ++i) found = found || (sources[i] && settings_.trigger_line == sources[i]);
        const std::string all = sources ? joinStrings(sources, n) : "none";
        g_free(sources);
        if (!found)
            fail(BINOCLE_ERR_INVALID_ARGUMENT, "trigger_line = " + settings_.trigger_line + " not offered (the camera offers: " + all + ")");
        arv_camera_set_trigger(camera_, settings_.trigger_line.c_str(), error.out());
        if (error) fail(BINOCLE_ERR_DEVICE, "trigger_line = " + settings_.trigger_line + " refused: " + error.message());
        break;
    }
    }
}

// What the camera will really send, then its stream and the control-lost watch.
void Camera::openStream() {
    GErrorSlot error;
    ArvDevice *device = arv_camera_get_device(camera_);
    const PixelFormat &format = *settings_.format;
    width_ = static_cast<int>(arv_camera_get_integer(camera_, "Width", error.out()));
    height_ = static_cast<int>(arv_camera_get_integer(camera_, "Height", error.out()));
    const ArvPixelFormat current = arv_camera_get_pixel_format(camera_, error.out());
    if (current != format.arv) fail(BINOCLE_ERR_DEVICE, "pixel_format = " + std::string(format.name) + " was not applied");
    payload_ = arv_camera_get_payload(camera_, error.out());
    if (error || width_ <= 0 || height_ <= 0 || payload_ == 0) fail(BINOCLE_ERR_DEVICE, "cannot read its image size: " + error.message());
    if (payload_ < static_cast<size_t>(width_) * height_ * format.bytes_per_pixel)
        fail(BINOCLE_ERR_DEVICE, "payload of " + std::to_string(payload_) + " bytes is too small for " + std::to_string(width_) + "x" +
                                     std::to_string(height_) + " " + format.name);

    // Aravis's packet socket sees every packet on the interface until its filter is set: a
    // camera reopened while another streams may take that one's frame ids as its own and
    // drop its own frames as "late" (up to 100 of them). The UDP socket sees only its port.
    if (arv_camera_is_gv_device(camera_))
        arv_camera_gv_set_stream_options(camera_, settings_.packet_socket ? ARV_GV_STREAM_OPTION_NONE
                                                                           : ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
    auto *notifierCopy = new std::shared_ptr<Notifier>(notifier_);
    stream_ = arv_camera_create_stream_full(camera_, &Camera::onStreamEvent, notifierCopy,
                                            [](void *p) { delete static_cast<std::shared_ptr<Notifier> *>(p); }, error.out());
    if (!stream_) fail(BINOCLE_ERR_DEVICE, "cannot open its stream: " + error.message());
    home_ = std::make_shared<BufferHome>(stream_);
    g_object_unref(stream_); // home_ holds the reference now
    if (ARV_IS_GV_STREAM(stream_)) configureStreamSocket();

    if (ARV_IS_GV_DEVICE(device)) {
        auto *lostCopy = new std::shared_ptr<LostState>(lost_);
        controlLostHandler_ = g_signal_connect_data(
            device, "control-lost", G_CALLBACK(&Camera::onControlLost), lostCopy,
            [](gpointer p, GClosure *) { delete static_cast<std::shared_ptr<LostState> *>(p); }, GConnectFlags(0));
    }
}

// Why the defaults: Aravis leaves the stream socket's receive buffer at the kernel's default
// (net.core.rmem_default, 208 KiB here), less than one 640x480 image. A camera sends each
// image as one burst of packets; whenever the stream thread is not scheduled for the few
// milliseconds a burst lasts (a busy machine), the kernel drops what does not fit, and at
// 20-30 fps nearly every image lost packets. The fix is a buffer with room for several
// images. Larger packets (the largest the path carries, found with Aravis's test packets)
// cut the number of packets, and so the receiver's work, per image.
void Camera::configureTransport() {
    GErrorSlot error;
    if (settings_.packet_size) {
        arv_camera_gv_set_packet_size(camera_, static_cast<gint>(*settings_.packet_size), error.out());
        if (error) fail(BINOCLE_ERR_INVALID_ARGUMENT, "packet_size = " + std::to_string(*settings_.packet_size) + " refused: " + error.message());
        const gint64 now = arv_camera_gv_get_packet_size(camera_, error.out());
        if (now != *settings_.packet_size)
            fail(BINOCLE_ERR_INVALID_ARGUMENT, "packet_size = " + std::to_string(*settings_.packet_size) + " not accepted (the camera set " +
                                                   std::to_string(now) + ")");
    } else {
        // Test packets of decreasing size: the largest that reaches this host unfragmented.
        // A camera without test packets keeps its own size.
        arv_camera_gv_auto_packet_size(camera_, error.out());
    }
    packetSize_ = arv_camera_gv_get_packet_size(camera_, error.out());
    if (settings_.packet_delay_ns) {
        if (!arv_camera_is_feature_available(camera_, "GevSCPD", nullptr))
            fail(BINOCLE_ERR_UNSUPPORTED, "packet_delay_ns = " + std::to_string(*settings_.packet_delay_ns) + ": the camera has no GevSCPD");
        arv_camera_gv_set_packet_delay(camera_, *settings_.packet_delay_ns, error.out());
        if (error)
            fail(BINOCLE_ERR_INVALID_ARGUMENT, "packet_delay_ns = " + std::to_string(*settings_.packet_delay_ns) + " refused: " + error.message());
    }
}

void Camera::configureStreamSocket() {
    // Room for as many images as the stream has buffers: a burst that waits for the stream
    // thread is never larger than what the buffers could take anyway.
    std::ifstream limit("/proc/sys/net/core/rmem_max");
    if (!(limit >> socketBufferLimitBytes_)) socketBufferLimitBytes_ = 0;
    if (settings_.socket_buffer_bytes > 0) {
        socketBufferBytes_ = settings_.socket_buffer_bytes;
    } else {
        // What the kernel grants, but never less than two images (a warning tells how to
        // raise the limit then).
        socketBufferBytes_ = static_cast<int64_t>(payload_) * settings_.buffers;
        if (socketBufferLimitBytes_ > 0)
            socketBufferBytes_ = std::min(socketBufferBytes_, std::max(socketBufferLimitBytes_, 2 * static_cast<int64_t>(payload_)));
    }
    socketBufferBytes_ = std::min<int64_t>(socketBufferBytes_, G_MAXINT);
    g_object_set(stream_, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_FIXED, "socket-buffer-size",
                 static_cast<gint>(socketBufferBytes_), "packet-resend",
                 settings_.packet_resend ? ARV_GV_STREAM_PACKET_RESEND_ALWAYS : ARV_GV_STREAM_PACKET_RESEND_NEVER, nullptr);
}

void Camera::onStreamEvent(void *data, ArvStreamCallbackType type, ArvBuffer *) {
    if (type == ARV_STREAM_CALLBACK_TYPE_BUFFER_DONE) (*static_cast<std::shared_ptr<Notifier> *>(data))->notify();
}

void Camera::onControlLost(ArvGvDevice *, void *data) {
    auto &state = *static_cast<std::shared_ptr<LostState> *>(data);
    {
        std::lock_guard<std::mutex> lock(state->mutex);
        if (state->reason.empty()) state->reason = "control lost: heartbeat unanswered";
    }
    if (state->notifier) state->notifier->notify();
}

void Camera::start() {
    if (!buffersQueued_) {
        for (int i = 0; i < settings_.buffers; ++i) home_->push(arv_buffer_new_allocate(payload_));
        buffersQueued_ = true;
    }
    GErrorSlot error;
    arv_camera_start_acquisition(camera_, error.out());
    if (error) fail(BINOCLE_ERR_DEVICE, "AcquisitionStart failed: " + error.message());
    acquiring_ = true;
}

void Camera::stop() {
    if (!acquiring_) return;
    acquiring_ = false;
    if (lostReason().empty()) arv_camera_stop_acquisition(camera_, nullptr);
}

ArvBuffer *Camera::tryPop() {
    ArvStream *s = stream_;
    return s ? arv_stream_try_pop_buffer(s) : nullptr;
}

void Camera::softwareTrigger() {
    GErrorSlot error;
    arv_camera_software_trigger(camera_, error.out());
    if (error) fail(BINOCLE_ERR_DEVICE, "software trigger failed: " + error.message());
}

std::string Camera::lostReason() const {
    std::lock_guard<std::mutex> lock(lost_->mutex);
    return lost_->reason;
}

void Camera::markLost(const std::string &why) {
    {
        std::lock_guard<std::mutex> lock(lost_->mutex);
        if (lost_->reason.empty()) lost_->reason = why;
    }
    notifier_->notify();
}

StreamCounters Camera::counters() const {
    StreamCounters c;
    if (!stream_) return c;
    guint64 completed = 0, failed = 0, underruns = 0;
    arv_stream_get_statistics(stream_, &completed, &failed, &underruns);
    c.completed = completed;
    c.failed = failed;
    c.underruns = underruns;
    if (ARV_IS_GV_STREAM(stream_)) {
        guint64 resent = 0, missing = 0;
        arv_gv_stream_get_statistics(ARV_GV_STREAM(stream_), &resent, &missing);
        c.resent_packets = resent;
        c.missing_packets = missing;
    }
    return c;
}

// ---- TriggerWorker ---------------------------------------------------------------------

TriggerWorker::TriggerWorker(std::shared_ptr<Camera> camera) : camera_(std::move(camera)) {
    thread_ = std::thread([this] { loop(); });
}

TriggerWorker::~TriggerWorker() {
    wake(stop_);
    thread_.join();
}

void TriggerWorker::request() { wake(pending_); }

void TriggerWorker::wake(bool &flag) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        flag = true;
    }
    cv_.notify_all();
}

void TriggerWorker::loop() {
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

} // namespace binocle::gige
