// SPDX-License-Identifier: MIT
// The helper's side of `isolation: process`: binocle-plugin-helper loads one plugin file,
// serves its instance over the socket, and forwards what it logs, prints and reports.
#include "host/helper_protocol.hpp"
#include "host/isolation.hpp"

#include "core/log.hpp"

#include <cerrno>
#include <csignal>
#include <fcntl.h>
#include <map>
#include <mutex>
#include <poll.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <thread>
#include <unistd.h>

namespace binocle {

namespace {

using namespace helper;

// The socket to the host; the plugin's own threads may log while a call is served.
std::mutex g_sendMutex;
int g_socket = -1;

bool send(const std::string &msg) {
    std::lock_guard<std::mutex> lock(g_sendMutex);
    return sendMessage(g_socket, msg);
}

void sendLog(LogOrigin origin, int32_t level, const std::string &text) {
    send(Writer().put<uint32_t>(kLog).put<uint8_t>(origin).put<int32_t>(level).str(text).data());
}

// The helper's own spdlog lines (they name the plugin already) go to the host's log.
class ForwardSink : public spdlog::sinks::base_sink<std::mutex> {
protected:
    void sink_it_(const spdlog::details::log_msg &msg) override {
        int32_t level = BINOCLE_LOG_ERROR;
        if (msg.level <= spdlog::level::debug) level = BINOCLE_LOG_DEBUG;
        else if (msg.level == spdlog::level::info) level = BINOCLE_LOG_INFO;
        else if (msg.level == spdlog::level::warn) level = BINOCLE_LOG_WARNING;
        sendLog(kFromHelper, level, std::string(msg.payload.data(), msg.payload.size()));
    }
    void flush_() override {}
};

// What the plugin writes to stdout (info) and stderr (warning) reaches the host's log as
// lines tagged with the plugin, not as raw bytes on Binocle's terminal. A thread forwards
// what comes while the helper waits; drain() forwards what a call wrote before its reply
// goes out, so that the host sees a call's lines during that call.
class OutputForwarder {
public:
    OutputForwarder() {
        int out[2], err[2];
        if (::pipe2(out, O_CLOEXEC | O_NONBLOCK) != 0) return;
        if (::pipe2(err, O_CLOEXEC | O_NONBLOCK) != 0) {
            ::close(out[0]);
            ::close(out[1]);
            return;
        }
        // The write ends block like a terminal would; only our reads must not.
        for (int w : {out[1], err[1]}) ::fcntl(w, F_SETFL, ::fcntl(w, F_GETFL) & ~O_NONBLOCK);
        std::fflush(nullptr);
        ::dup2(out[1], 1);
        ::dup2(err[1], 2);
        ::close(out[1]);
        ::close(err[1]);
        fds_[0] = out[0];
        fds_[1] = err[0];
        thread_ = std::thread([this] { run(); });
    }
    // Points stdout and stderr elsewhere (the pipes' last writers) and waits for the last
    // lines to go out.
    ~OutputForwarder() {
        if (!thread_.joinable()) return;
        std::fflush(nullptr);
        const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
        ::dup2(null, 1);
        ::dup2(null, 2);
        ::close(null);
        thread_.join();
        for (int fd : fds_)
            if (fd >= 0) ::close(fd);
    }
    void drain() {
        if (!thread_.joinable()) return;
        std::fflush(nullptr);
        std::lock_guard<std::mutex> lock(mutex_);
        for (int i = 0; i < 2; ++i) readAvailable(i);
    }

private:
    // Reads what the pipe holds; sends whole lines (and the rest at end of file). Returns
    // false at end of file. Holds mutex_.
    bool readAvailable(int i) {
        bool open = true;
        for (;;) {
            char buf[4096];
            const ssize_t n = ::read(fds_[i], buf, sizeof buf);
            if (n > 0) {
                pending_[i].append(buf, static_cast<size_t>(n));
                continue;
            }
            if (n < 0 && errno == EINTR) continue;
            open = n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
            break;
        }
        for (size_t nl; (nl = pending_[i].find('\n')) != std::string::npos || (!open && !pending_[i].empty());) {
            const std::string line = pending_[i].substr(0, nl);
            pending_[i].erase(0, nl == std::string::npos ? std::string::npos : nl + 1);
            sendLog(kFromOutput, i == 0 ? BINOCLE_LOG_INFO : BINOCLE_LOG_WARNING, line);
        }
        return open;
    }
    void run() {
        pollfd fds[2] = {{fds_[0], POLLIN, 0}, {fds_[1], POLLIN, 0}};
        while (fds[0].fd >= 0 || fds[1].fd >= 0) {
            if (::poll(fds, 2, -1) < 0) {
                if (errno == EINTR) continue;
                break;
            }
            std::lock_guard<std::mutex> lock(mutex_);
            for (int i = 0; i < 2; ++i)
                if (fds[i].fd >= 0 && (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) && !readAvailable(i))
                    fds[i].fd = -1; // end of file: stop polling it
        }
    }
    int fds_[2] = {-1, -1};
    std::string pending_[2];
    std::mutex mutex_;
    std::thread thread_;
};

// A host's region, mapped here.
struct Mapping {
    void *data = nullptr;
    size_t bytes = 0;
    ~Mapping() {
        if (data) ::munmap(data, bytes);
    }
    uint8_t *base() const { return static_cast<uint8_t *>(data); }
};

// One plugin instance and what it needs between calls.
struct Served {
    const PluginRecord *record = nullptr;
    std::string loadError;
    std::unique_ptr<Source> source;
    std::unique_ptr<Matcher> matcher;
    std::unique_ptr<CloudTransform> transform;
    std::unique_ptr<Evaluator> evaluator;
    std::unique_ptr<LentFrame> pending; // grabbed, waiting for a region large enough
    std::map<uint32_t, Mapping> regions;
    std::pair<bool, std::string> calibration{false, ""}, rig{false, ""};

    void reset() {
        pending.reset();
        source.reset();
        matcher.reset();
        transform.reset();
        evaluator.reset();
    }
    Mapping &region(uint32_t id, uint64_t bytes, int fd) {
        Mapping &m = regions[id];
        if (fd >= 0) {
            if (m.data) ::munmap(m.data, m.bytes);
            m.data = nullptr;
            m.bytes = 0;
            void *p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
            ::close(fd);
            if (p == MAP_FAILED) throw Error(std::string("helper: cannot map the shared memory: ") + std::strerror(errno));
            m.data = p;
            m.bytes = bytes;
        }
        return m;
    }
    template <class T>
    T &need(std::unique_ptr<T> &instance, const char *what) {
        if (!instance) throw Error(std::string("helper: ") + what + " before create (or for another kind of plugin)");
        return *instance;
    }
};

HostSink forwardingSink() {
    HostSink sink;
    sink.log = [](int32_t level, const std::string &text) { sendLog(kFromPlugin, level, text); };
    sink.metric = [](const std::string &name, double value, const std::string &unit) {
        send(Writer().put<uint32_t>(kMetric).str(name).put<double>(value).str(unit).data());
    };
    sink.text = [](const std::string &name, const std::string &text) {
        send(Writer().put<uint32_t>(kText).str(name).str(text).data());
    };
    return sink;
}

void create(Served &s, Reader &r) {
    const auto kind = r.get<int32_t>();
    if (s.record->kind != kind)
        throw Error("plugin file " + s.record->path + " is a " + kindName(s.record->kind) + " plugin now, not a " +
                    kindName(kind));
    const ParamValues params = decodeParams(r); // in this process: no isolation here
    s.reset();
    switch (kind) {
    case BINOCLE_KIND_STEREO_SOURCE:
        s.source = std::make_unique<Source>(*s.record, params);
        s.source->setSink(forwardingSink());
        break;
    case BINOCLE_KIND_MATCHER:
        s.matcher = std::make_unique<Matcher>(*s.record, params);
        s.matcher->setSink(forwardingSink());
        break;
    case BINOCLE_KIND_CLOUD_TRANSFORM:
        s.transform = std::make_unique<CloudTransform>(*s.record, params);
        s.transform->setSink(forwardingSink());
        break;
    case BINOCLE_KIND_EVALUATOR: s.evaluator = std::make_unique<Evaluator>(*s.record, params, forwardingSink()); break;
    default: throw Error("helper: unknown plugin kind");
    }
}

void compute(Served &s, Reader &r, const Mapping &m) {
    Matcher &matcher = s.need(s.matcher, "compute");
    const auto width = r.get<int32_t>();
    const auto height = r.get<int32_t>();
    const auto type = r.get<int32_t>();
    const auto imageBytes = r.get<uint64_t>();
    if (width <= 0 || height <= 0 || (type != CV_8UC1 && type != CV_8UC3))
        throw Error("helper: malformed compute request");
    const uint64_t row = static_cast<uint64_t>(width) * CV_ELEM_SIZE(type);
    const uint64_t disparityBytes = static_cast<uint64_t>(width) * height * sizeof(float);
    if (row * height > imageBytes || imageBytes > m.bytes / 2 || 2 * imageBytes + disparityBytes > m.bytes)
        throw Error("helper: images do not fit the shared memory");
    uint8_t *base = m.base();
    cv::Mat left(height, width, type, base), right(height, width, type, base + imageBytes);
    cv::Mat disparity(height, width, CV_32F, base + 2 * imageBytes);
    disparity.setTo(cv::Scalar(BINOCLE_INVALID_DISPARITY));
    matcher.computeInto(left, right, disparity);
}

void grab(Served &s, Reader &r, const Mapping &m, Writer &out) {
    Source &source = s.need(s.source, "grab");
    const auto timeout = r.get<int32_t>();
    if (!s.pending) {
        s.pending = source.grab(timeout);
        if (!s.pending)
            throw PluginError("source plugin '" + s.record->name + "': end of stream", BINOCLE_ERR_END_OF_STREAM);
    }
    // The wrapper checked the frame; its planes are copied into the host's region, and
    // the frame goes back to the plugin at once.
    const binocle_stereo_frame &f = s.pending->raw();
    Layout layout;
    Writer body;
    body.put<uint64_t>(f.sequence).put<int64_t>(f.timestamp_left_ns).put<int64_t>(f.timestamp_right_ns);
    putImage(body, layout.place(f.left));
    putImage(body, layout.place(f.right));
    body.put<int32_t>(f.extra_count);
    for (int32_t i = 0; i < f.extra_count; ++i) {
        body.str(f.extras[i].name ? f.extras[i].name : "");
        putImage(body, layout.place(f.extras[i].image));
    }
    body.cstr(f.metadata);
    out.put<uint64_t>(layout.bytes());
    if (layout.bytes() > m.bytes) return; // the host makes the region larger and asks again
    layout.copyInto(m.base());
    out.raw(body.data());
    s.pending.reset();
}

binocle_cloud cloudAt(Reader &r, const Mapping &m) {
    binocle_cloud c{};
    c.count = r.get<int64_t>();
    c.image_width = r.get<int32_t>();
    c.image_height = r.get<int32_t>();
    c.frame = r.get<int32_t>();
    if (c.count < 0) throw Error("helper: malformed cloud");
    const uint64_t n = static_cast<uint64_t>(c.count);
    c.xyz = reinterpret_cast<float *>(arrayAt(r.get<uint64_t>(), 3 * n * sizeof(float), m.base(), m.bytes));
    const bool rgb = r.get<uint8_t>() != 0;
    const auto rgbAt = r.get<uint64_t>();
    if (rgb) c.rgb = arrayAt(rgbAt, 3 * n, m.base(), m.bytes);
    const bool pixel = r.get<uint8_t>() != 0;
    const auto pixelAt = r.get<uint64_t>();
    if (pixel) c.pixel = reinterpret_cast<int32_t *>(arrayAt(pixelAt, n * sizeof(int32_t), m.base(), m.bytes));
    return c;
}

void apply(Served &s, Reader &r, const Mapping &m, Writer &out) {
    CloudTransform &transform = s.need(s.transform, "apply");
    binocle_cloud c = cloudAt(r, m);
    transform.apply(c); // the wrapper refuses a garbage cloud
    const auto offset = [&](const void *p) { return p ? static_cast<uint64_t>(static_cast<const uint8_t *>(p) - m.base()) : 0; };
    out.put<int64_t>(c.count).put<int32_t>(c.frame).put<uint64_t>(offset(c.xyz)).put<uint64_t>(offset(c.rgb));
    out.put<uint64_t>(offset(c.pixel));
}

void evaluate(Served &s, Reader &r, const Mapping &m) {
    Evaluator &evaluator = s.need(s.evaluator, "evaluate");
    binocle_stereo_frame frame{};
    std::vector<binocle_named_image> extras;
    std::vector<std::string> names;
    std::string metadata;
    const bool hasFrame = r.get<uint8_t>() != 0;
    if (hasFrame) {
        frame.struct_size = sizeof frame;
        frame.sequence = r.get<uint64_t>();
        frame.timestamp_left_ns = r.get<int64_t>();
        frame.timestamp_right_ns = r.get<int64_t>();
        frame.left = getImage(r, m.base(), m.bytes);
        frame.right = getImage(r, m.base(), m.bytes);
        const auto count = r.get<int32_t>();
        if (count < 0 || count > 64) throw Error("helper: malformed frame");
        names.reserve(static_cast<size_t>(count));
        for (int32_t i = 0; i < count; ++i) {
            names.push_back(r.str());
            extras.push_back({names.back().c_str(), getImage(r, m.base(), m.bytes)});
        }
        frame.extras = extras.empty() ? nullptr : extras.data();
        frame.extra_count = count;
        const auto [hasMetadata, text] = r.cstr();
        metadata = text;
        frame.metadata = hasMetadata ? metadata.c_str() : nullptr;
    }
    binocle_image images[3];
    bool has[3];
    for (int i = 0; i < 3; ++i) {
        has[i] = r.get<uint8_t>() != 0;
        if (has[i]) images[i] = getImage(r, m.base(), m.bytes);
    }
    binocle_cloud cloud{};
    const bool hasCloud = r.get<uint8_t>() != 0;
    if (hasCloud) cloud = cloudAt(r, m);
    for (auto *text : {&s.calibration, &s.rig})
        if (r.get<uint8_t>() == 0) *text = r.cstr(); // else: the same as before
    const auto [hasOutput, output] = r.cstr();
    binocle_eval_input in{};
    in.min_disparity = r.get<int32_t>();
    in.num_disparities = r.get<int32_t>();
    in.ground_pose_known = r.get<int32_t>();
    in.camera_height_mm = r.get<double>();
    in.inclination_deg = r.get<double>();
    in.struct_size = sizeof in;
    in.frame = hasFrame ? &frame : nullptr;
    in.rectified_left = has[0] ? &images[0] : nullptr;
    in.rectified_right = has[1] ? &images[1] : nullptr;
    in.disparity = has[2] ? &images[2] : nullptr;
    in.cloud = hasCloud ? &cloud : nullptr;
    in.calibration_yaml = s.calibration.first ? s.calibration.second.c_str() : nullptr;
    in.rig_yaml = s.rig.first ? s.rig.second.c_str() : nullptr;
    in.output_dir = hasOutput ? output.c_str() : nullptr;
    evaluator.evaluate(in);
}

} // namespace

int serveIsolatedPlugin(int fd, const std::string &path) {
    // The host may die first: a write to its socket must fail, not kill us silently.
    ::signal(SIGPIPE, SIG_IGN);
    g_socket = fd;
    auto logger = std::make_shared<spdlog::logger>("helper", std::make_shared<ForwardSink>());
    logger->set_level(spdlog::level::trace); // the host's logger chooses what it shows
    spdlog::set_default_logger(logger);
    OutputForwarder output;

    Served s;
    PluginHost host(std::vector<std::string>{});
    try {
        s.record = &host.load(path); // the library's constructors run here, never in Binocle
    } catch (const std::exception &e) {
        s.loadError = e.what();
    }
    std::string msg;
    int received = -1;
    while (receiveMessage(fd, msg, &received)) {
        int32_t rc = BINOCLE_OK;
        std::string message;
        Writer payload;
        try {
            Reader r(msg);
            const auto op = r.get<uint32_t>();
            const auto regionId = r.get<uint32_t>();
            const auto regionBytes = r.get<uint64_t>();
            if (op == kDestroy) {
                s.reset();
            } else {
                if (!s.loadError.empty()) throw PluginError(s.loadError, BINOCLE_ERR_NOT_FOUND);
                static Mapping none;
                const Mapping &m = regionId == kNoRegion ? none : s.region(regionId, regionBytes, received);
                received = -1;
                switch (op) {
                case kDescribe: encodeDescription(payload, *s.record->table, s.record->params()); break;
                case kCreate: create(s, r); break;
                case kCompute: compute(s, r, m); break;
                case kRange: {
                    const auto range = s.need(s.matcher, "disparity_range").disparityRange();
                    payload.put<int32_t>(range.first).put<int32_t>(range.second);
                    break;
                }
                case kStart: s.need(s.source, "start").start(); break;
                case kStop: s.need(s.source, "stop").stop(); break;
                case kGrab: grab(s, r, m, payload); break;
                case kCalibration: payload.str(s.need(s.source, "calibration").calibration()); break;
                case kStatistics: payload.str(s.need(s.source, "statistics").statistics()); break;
                case kApply: apply(s, r, m, payload); break;
                case kEvaluate: evaluate(s, r, m); break;
                case kFinish: s.need(s.evaluator, "finish").finish(); break;
                default: throw Error("helper: unknown request " + std::to_string(op));
                }
            }
        } catch (const PluginError &e) {
            rc = e.code();
            message = e.what();
        } catch (const std::exception &e) {
            rc = BINOCLE_ERR_INTERNAL;
            message = e.what();
        }
        if (received >= 0) ::close(received);
        received = -1;
        output.drain();
        if (!send(Writer().put<uint32_t>(kReply).put<int32_t>(rc).str(message).raw(payload.data()).data())) break;
    }
    s.reset();
    s.regions.clear();
    return 0;
}

} // namespace binocle
