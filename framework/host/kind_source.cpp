// SPDX-License-Identifier: MIT
// The stereo source kind: its descriptor, its instance in this process, behind a proxy,
// and in the helper process, and the Source wrapper.
#include "host/kind_source.hpp"

#include "host/instance_support.hpp"
#include "host/isolated_side.hpp"
#include "host/kind_source_messages.hpp"
#include "host/isolation.hpp"
#include "host/plugin_kinds.hpp"

#include <mutex>

namespace binocle {

namespace {

enum SourceOp : uint32_t { kStart = wire::kFirstKindOp, kStop, kGrab, kCalibration, kStatistics };

} // namespace

// What a source instance does, wherever it runs.
class Source::Impl : public InstanceImpl {
public:
    virtual void start() = 0;
    virtual void stop() = 0;
    // nullptr at end of stream.
    virtual std::unique_ptr<LentFrame> grab(int32_t timeout_ms) = 0;
    virtual std::string calibration() = 0;
    virtual std::string statistics() = 0;
};

namespace {

class InProcessSource : public Source::Impl {
public:
    InProcessSource(const PluginRecord &record, const ParamValues &params, const std::shared_ptr<binocle_host> &host)
        : record_(record), api_(reinterpret_cast<const binocle_source_api *>(record.table)) {
        binocle_source *h = nullptr;
        const int32_t rc = api_->create(params.data(), params.size(), host.get(), &h);
        if (rc != BINOCLE_OK || !h) failCall(record_, "create", rc ? rc : BINOCLE_ERR_INTERNAL, api_->last_error(nullptr));
        // The handle outlives this object while frames are lent (each LentFrame holds it),
        // and keeps the library and the host block alive in turn.
        auto lib = record.library;
        auto api = api_;
        auto hostBlock = host;
        handle_ = std::shared_ptr<binocle_source>(h, [api, lib, hostBlock](binocle_source *p) {
            try {
                api->destroy(p);
            } catch (...) {
            }
        });
    }
    ~InProcessSource() override {
        if (handle_ && api_->stop) {
            try {
                api_->stop(handle_.get());
            } catch (...) {
            }
        }
    }
    void start() override {
        if (!api_->start) return;
        const int32_t rc = api_->start(handle_.get());
        if (rc != BINOCLE_OK) failCall(record_, "start", rc, api_->last_error(handle_.get()));
    }
    void stop() override {
        if (!api_->stop) return;
        const int32_t rc = api_->stop(handle_.get());
        if (rc != BINOCLE_OK) failCall(record_, "stop", rc, api_->last_error(handle_.get()));
    }
    std::unique_ptr<LentFrame> grab(int32_t timeout_ms) override {
        binocle_stereo_frame f{};
        f.struct_size = sizeof(f);
        const int32_t rc = api_->grab(handle_.get(), timeout_ms, &f);
        if (rc == BINOCLE_ERR_END_OF_STREAM) return nullptr;
        if (rc != BINOCLE_OK) failCall(record_, "grab", rc, api_->last_error(handle_.get()));
        // From here the frame is lent: any refusal below still gives it back.
        auto lent = std::make_unique<LentFrame>(handle_, api_, handle_.get(), f);
        if (std::string bad = checkFrame(f); !bad.empty())
            failCall(record_, "grab", BINOCLE_ERR_INTERNAL, ("returned an invalid frame: " + bad).c_str());
        return lent;
    }
    std::string calibration() override { return text("calibration", api_->calibration); }
    std::string statistics() override { return text("statistics", api_->statistics); }

private:
    using TextCall = binocle_result (*)(binocle_source *, const char **);
    std::string text(const char *what, TextCall entry) {
        if (!entry) return {};
        const char *yaml = nullptr;
        const int32_t rc = entry(handle_.get(), &yaml);
        if (rc != BINOCLE_OK) failCall(record_, what, rc, api_->last_error(handle_.get()));
        return yaml ? yaml : "";
    }
    const PluginRecord &record_;
    const binocle_source_api *api_;
    std::shared_ptr<binocle_source> handle_;
};

// Shared regions that frames are copied into, one per frame lent at a time. A slot stays
// busy while its LentFrame lives (on any thread); then the next grab may reuse it.
struct Slots {
    std::string name;
    std::mutex mutex;
    std::vector<std::unique_ptr<SharedRegion>> regions;
    std::vector<bool> busy;
    SharedRegion &take(size_t &index) {
        std::lock_guard<std::mutex> lock(mutex);
        for (index = 0; index < busy.size() && busy[index]; ++index) {
        }
        if (index == busy.size()) {
            regions.push_back(std::make_unique<SharedRegion>(name, static_cast<uint32_t>(index)));
            busy.push_back(false);
        }
        busy[index] = true;
        return *regions[index];
    }
    void give(size_t index) {
        std::lock_guard<std::mutex> lock(mutex);
        busy[index] = false;
    }
};

// What a LentFrame of an isolated source holds: its slot, the names and texts.
struct FrameCopy {
    std::function<void()> release;
    wire::FrameTexts texts;
    ~FrameCopy() {
        if (release) release();
    }
};

// A restart re-creates the source with the same settings and starts it again when it
// was started: the grab that crashed is lost (counted), and the next frame is the new
// instance's first (a camera's next image; a file source begins again).
class SourceProxy : public Proxied<Source::Impl> {
public:
    SourceProxy(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation,
                const std::shared_ptr<binocle_host> &host)
        : Proxied(record, params, isolation, host), slots_(std::make_shared<Slots>()) {
        slots_->name = record.name;
    }
    void start() override {
        retried([&] { call(kStart); });
        started_ = true;
    }
    void stop() override {
        started_ = false; // a restart during stop leaves the new instance stopped
        guarded([&] { call(kStop); });
    }
    // Waits timeout_ms for a pair; its watchdog is timeout_ms + call_timeout_ms. The frame
    // is a copy in shared memory (the helper process gives the plugin its frame back at
    // once).
    std::unique_ptr<LentFrame> grab(int32_t timeout_ms) override {
        const int32_t watchdog = options().call_timeout_ms > 0 ? options().call_timeout_ms + std::max(timeout_ms, 0) : 0;
        const std::string limitText = "its wait of " + std::to_string(timeout_ms) + " ms + call_timeout_ms";
        size_t slot = 0;
        SharedRegion &region = slots_->take(slot);
        auto copy = std::make_shared<FrameCopy>();
        auto slots = slots_;
        copy->release = [slots, slot] { slots->give(slot); };
        std::unique_ptr<LentFrame> out;
        wire::Writer request;
        wire::putGrabRequest(request, timeout_ms);
        try {
            retried([&] {
                for (;;) {
                    Reply r = call(kGrab, request.data(), &region, watchdog, limitText.c_str());
                    const auto need = r.payload.get<uint64_t>();
                    if (need > region.size()) {
                        region.reserve(need); // the helper process keeps the frame until it fits
                        continue;
                    }
                    out = std::make_unique<LentFrame>(copy, wire::getFrame(r.payload, region.region(), copy->texts));
                    return;
                }
            });
        } catch (const PluginError &e) {
            if (e.code() == BINOCLE_ERR_END_OF_STREAM) return nullptr;
            throw;
        }
        return out;
    }
    std::string calibration() override { return text(kCalibration); }
    std::string statistics() override { return text(kStatistics); }

private:
    std::string text(uint32_t op) {
        std::string text;
        retried([&] { text = call(op).payload.str(); });
        return text;
    }
    void afterRestart() override {
        if (started_) call(kStart);
    }
    std::shared_ptr<Slots> slots_; // shared with the frames still lent
    bool started_ = false;
};

class ServedSource : public ServedThrough<Source> {
public:
    ServedSource(const PluginRecord &record, const ParamValues &params, HostSink sink)
        : ServedThrough(record, params, std::move(sink)), record_(record) {}
    void call(uint32_t op, wire::Reader &r, wire::Region m, wire::Writer &out) override {
        switch (op) {
        case kStart: return instance_.start();
        case kStop: return instance_.stop();
        case kGrab: return grab(wire::getGrabRequest(r), m, out);
        case kCalibration: out.str(instance_.calibration()); return;
        case kStatistics: out.str(instance_.statistics()); return;
        default: throw Error("helper: unknown source request " + std::to_string(op));
        }
    }

private:
    void grab(int32_t timeout_ms, wire::Region m, wire::Writer &out) {
        if (!pending_) {
            pending_ = instance_.grab(timeout_ms);
            if (!pending_) throw PluginError("source plugin '" + record_.name + "': end of stream", BINOCLE_ERR_END_OF_STREAM);
        }
        // The wrapper checked the frame; its planes are copied into the host's region, and
        // the frame goes back to the plugin at once.
        wire::Layout layout;
        wire::Writer body;
        wire::putFrame(body, layout, pending_->raw());
        out.put<uint64_t>(layout.bytes());
        if (layout.bytes() > m.bytes) return; // the host makes the region larger and asks again
        layout.copyInto(m.base);
        out.raw(body.data());
        pending_.reset();
    }
    const PluginRecord &record_;
    std::unique_ptr<LentFrame> pending_; // grabbed, waiting for a region large enough
};

} // namespace

// ---- The wrapper ------------------------------------------------------------------------------

Source::Source(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation)
    : PluginInstanceBase(record), impl_(choose<Impl, InProcessSource, SourceProxy>(record_, params, isolation)) {}

Source::~Source() = default;

void Source::start() { impl_->start(); }
void Source::stop() { impl_->stop(); }
std::unique_ptr<LentFrame> Source::grab(int32_t timeout_ms) { return impl_->grab(timeout_ms); }
std::string Source::calibration() { return impl_->calibration(); }
std::string Source::statistics() { return impl_->statistics(); }

std::string Source::enumerateDevices(const PluginRecord &record) {
    auto api = reinterpret_cast<const binocle_source_api *>(record.table);
    if (!api->enumerate_devices) return "[]";
    const auto host = defaultHost(record.name);
    const char *yaml = nullptr;
    const int32_t rc = api->enumerate_devices(host.get(), &yaml);
    if (rc != BINOCLE_OK) {
        const char *m = api->last_error(nullptr);
        throw PluginError("source plugin '" + record.name + "' (" + record.path + "): enumerate_devices failed (" +
                              resultName(rc) + ")" + (m && *m ? ": " + std::string(m) : ""),
                          rc);
    }
    return yaml ? yaml : "[]";
}

// ---- The descriptor ---------------------------------------------------------------------------

const PluginKind &sourceKind() {
    using T = binocle_source_api;
    static const PluginKind kind = tableKind<T>(
        BINOCLE_KIND_STEREO_SOURCE, "source", "source", PluginKind::InRig::One,
        {{1, BINOCLE_END_OF(T, enumerate_devices), "enumerate_devices"}},
        {{"start", offsetof(T, start), false, kStart},
         {"stop", offsetof(T, stop), false, kStop},
         {"grab", offsetof(T, grab), true, kGrab},
         {"release_frame", offsetof(T, release_frame), true, 0},
         {"calibration", offsetof(T, calibration), false, kCalibration},
         {"statistics", offsetof(T, statistics), false, kStatistics},
         {"enumerate_devices", offsetof(T, enumerate_devices), false, 0}},
        "that grab is lost; the source is created (and started) again", &serveAs<ServedSource>);
    return kind;
}

} // namespace binocle
