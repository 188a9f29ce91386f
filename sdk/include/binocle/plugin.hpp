// SPDX-License-Identifier: MIT
// Binocle SDK: write a plugin as an ordinary C++ class and export it with one macro.
//
//   class MyMatcher : public binocle::sdk::Matcher {
//   public:
//       static std::vector<binocle_param_desc> parameters() {
//           return {binocle::sdk::Param::integer("window_px", "5").min(1).odd()
//                       .help("matching window").unit("px")};
//       }
//       MyMatcher(const binocle::sdk::CheckedParams &p, binocle::sdk::Host &host)
//           : window_(static_cast<int>(p.integer("window_px"))) {}
//       void compute(const binocle_image &l, const binocle_image &r, binocle_image &d) override;
//   };
//   BINOCLE_EXPORT_MATCHER(MyMatcher, "my_matcher", "1.0.0", "What it does")
//
// The constructor gets the settings checked against parameters() (settings.hpp): a
// setting the host did not pass reads as its default, and a value outside the table
// fails `create` with "my_matcher: window_px = 4: expected an odd integer >= 1". A
// constructor taking `const Params &` (the raw values, as earlier SDKs handed them)
// still builds, and is called after the same check.
//
// Exceptions thrown by the class are caught at the boundary and turned into a result
// code (binocle::sdk::Error carries its own) and a message the host can ask for.
// This header needs only the C++17 standard library.
#pragma once

#include <binocle/abi.h>
#include <binocle/error.hpp>
#include <binocle/settings.hpp>

#include <cstring>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace binocle::sdk {

// ---- Host services -----------------------------------------------------------------

class Host {
public:
    explicit Host(const binocle_host *h) : h_(h) {}
    void log(int32_t level, const std::string &msg) const {
        if (h_ && h_->log) h_->log(h_->context, level, msg.c_str());
    }
    // Shown by `binocle --log-level debug ...`, tagged with the plugin's name.
    void debug(const std::string &msg) const { log(BINOCLE_LOG_DEBUG, msg); }
    void info(const std::string &msg) const { log(BINOCLE_LOG_INFO, msg); }
    void warning(const std::string &msg) const { log(BINOCLE_LOG_WARNING, msg); }
    void metric(const std::string &name, double value, const std::string &unit = "") const {
        if (h_ && h_->report_metric) h_->report_metric(h_->context, name.c_str(), value, unit.c_str());
    }
    void text(const std::string &name, const std::string &text) const {
        if (h_ && h_->report_text) h_->report_text(h_->context, name.c_str(), text.c_str());
    }

private:
    const binocle_host *h_;
};

// ---- Images --------------------------------------------------------------------------

inline int bytesPerPixel(int32_t format) {
    switch (format) {
    case BINOCLE_PIXEL_GRAY8: return 1;
    case BINOCLE_PIXEL_GRAY16: return 2;
    case BINOCLE_PIXEL_BGR8:
    case BINOCLE_PIXEL_RGB8: return 3;
    case BINOCLE_PIXEL_FLOAT32: return 4;
    default: return 0;
    }
}

inline binocle_image makeImage(int32_t width, int32_t height, int32_t format, void *data, int32_t stride_bytes = 0) {
    binocle_image im{};
    im.width = width;
    im.height = height;
    im.format = format;
    im.stride_bytes = stride_bytes > 0 ? stride_bytes : width * bytesPerPixel(format);
    im.data = data;
    return im;
}

// "GRAY8", ... for messages.
inline std::string pixelFormatName(int32_t format) {
    switch (format) {
    case BINOCLE_PIXEL_GRAY8: return "GRAY8";
    case BINOCLE_PIXEL_GRAY16: return "GRAY16";
    case BINOCLE_PIXEL_BGR8: return "BGR8";
    case BINOCLE_PIXEL_RGB8: return "RGB8";
    case BINOCLE_PIXEL_FLOAT32: return "FLOAT32";
    default: return "unknown format " + std::to_string(format);
    }
}

// "640x480", for messages.
inline std::string sizeText(const binocle_image &im) {
    return std::to_string(im.width) + "x" + std::to_string(im.height);
}

// Throws (BINOCLE_ERR_INVALID_ARGUMENT) unless `im` is a usable view: positive size, data,
// stride covering a row. `role` names it: "left", "disparity".
inline void checkImage(const binocle_image &im, const std::string &role) {
    if (im.width <= 0 || im.height <= 0)
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT, role + " image is " + sizeText(im) + ": expected a positive size");
    if (!im.data) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, role + " image has no pixels (data is NULL)");
    const int64_t row = static_cast<int64_t>(im.width) * bytesPerPixel(im.format);
    if (im.stride_bytes < row)
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT, role + " image stride is " + std::to_string(im.stride_bytes) +
                                                      " bytes: expected at least " + std::to_string(row) +
                                                      " (width x bytes per pixel)");
}

// A matcher's arguments checked as the ABI states them (matcher.h): left GRAY8, BGR8 or
// RGB8; right the same format and size; disparity FLOAT32 of that size; all usable views.
// `prefix` starts each message ("sgm: ").
inline void checkMatcherImages(const binocle_image &left, const binocle_image &right, const binocle_image &disparity,
                               const std::string &prefix = "") {
    auto refuse = [&](const std::string &what) { throw Error(BINOCLE_ERR_INVALID_ARGUMENT, prefix + what); };
    if (left.format != BINOCLE_PIXEL_GRAY8 && left.format != BINOCLE_PIXEL_BGR8 && left.format != BINOCLE_PIXEL_RGB8)
        refuse("left image is " + pixelFormatName(left.format) + ": expected GRAY8, BGR8 or RGB8");
    if (right.format != left.format)
        refuse("right image is " + pixelFormatName(right.format) + ": expected " + pixelFormatName(left.format) +
               ", the format of the left image");
    if (right.width != left.width || right.height != left.height)
        refuse("right image is " + sizeText(right) + ": expected " + sizeText(left) + ", the size of the left image");
    if (disparity.format != BINOCLE_PIXEL_FLOAT32)
        refuse("disparity image is " + pixelFormatName(disparity.format) + ": expected FLOAT32");
    if (disparity.width != left.width || disparity.height != left.height)
        refuse("disparity image is " + sizeText(disparity) + ": expected " + sizeText(left) + ", the size of the left image");
    try {
        checkImage(left, "left");
        checkImage(right, "right");
        checkImage(disparity, "disparity");
    } catch (const Error &e) {
        refuse(e.what());
    }
}

// ---- StereoSource ----------------------------------------------------------------------

// A frame a C++ source hands out. The SDK lends it to the host and destroys it when
// the host releases it: keep the pixel memory alive in `owner` (a vector, a cv::Mat,
// a driver buffer ...) and put any give-back action (re-queue a V4L2 buffer) in
// `onRelease`.
struct Frame {
    uint64_t sequence = 0;
    int64_t timestamp_left_ns = 0;
    int64_t timestamp_right_ns = 0;
    binocle_image left{};
    binocle_image right{};
    std::vector<std::pair<std::string, binocle_image>> extras;
    std::string metadata; // YAML, may be empty
    std::shared_ptr<void> owner;
    std::function<void()> onRelease;

    Frame() = default;
    Frame(const Frame &) = delete;
    Frame &operator=(const Frame &) = delete;
    ~Frame() {
        if (onRelease) onRelease();
    }
};

class StereoSource {
public:
    virtual ~StereoSource() = default;
    virtual void start() {}
    virtual void stop() {}
    // Next pair; throw Error(BINOCLE_ERR_END_OF_STREAM, ...) when exhausted,
    // Error(BINOCLE_ERR_TIMEOUT, ...) when nothing came in time.
    virtual std::unique_ptr<Frame> grab(int32_t timeout_ms) = 0;
    // OpenCV FileStorage YAML text, empty when unknown.
    virtual std::string calibration() { return {}; }
    // YAML text of stream statistics.
    virtual std::string statistics() { return {}; }
    // Hide this in a derived class to list devices (YAML sequence of maps with id, description).
    static std::string enumerateDevices(Host &) { return "[]"; }
};

class Matcher {
public:
    virtual ~Matcher() = default;
    virtual void compute(const binocle_image &left, const binocle_image &right, binocle_image &disparity) = 0;
    // {min_disparity, num_disparities}
    virtual std::pair<int32_t, int32_t> disparityRange() const { return {0, 0}; }
    // Named planes attached to the last compute's disparity (matcher.h: extras), each of
    // its size, e.g. {"disparity_filled", a GRAY8 view}: names and pixels the matcher
    // keeps until its next compute. None by default.
    virtual std::vector<binocle_named_image> extras() { return {}; }
};

class CloudTransform {
public:
    virtual ~CloudTransform() = default;
    virtual void apply(binocle_cloud &cloud) = 0;
};

class Evaluator {
public:
    virtual ~Evaluator() = default;
    virtual void evaluate(const binocle_eval_input &input) = 0;
    virtual void finish() {}
};

// ---- Boundary adaptors (implementation detail of the export macros) --------------------
namespace detail {

inline std::string &createError() {
    thread_local std::string message;
    return message;
}

// Runs f, turning any exception into a result code and a message stored in `error`.
template <class F>
binocle_result guard(std::string &error, F &&f) noexcept {
    try {
        f();
        return BINOCLE_OK;
    } catch (const Error &e) {
        try { error = e.what(); } catch (...) {}
        return e.code() == BINOCLE_OK ? BINOCLE_ERR_INTERNAL : e.code();
    } catch (const std::exception &e) {
        try { error = e.what(); } catch (...) {}
        return BINOCLE_ERR_INTERNAL;
    } catch (...) {
        try { error = "unknown exception"; } catch (...) {}
        return BINOCLE_ERR_INTERNAL;
    }
}

template <class T>
struct Instance {
    using Impl = T;
    explicit Instance(const binocle_host *h) : hostView(h) {}
    Host hostView;
    std::unique_ptr<T> impl;
    std::string error;
};

template <class T>
const std::vector<binocle_param_desc> &paramsOf() {
    static const std::vector<binocle_param_desc> p = T::parameters();
    return p;
}

// The plugin's name as its table gives it (set when the table is made, which the host
// asks for before any `create`): refusals of its settings start with it.
template <class T>
std::string &pluginNameOf() {
    static std::string name;
    return name;
}

// Which settings a plugin class's constructor takes: `const CheckedParams &` (the one
// way, what the in-tree plugins do) or `const Params &` (the SDK before CheckedParams
// was built for the plugin; still built, so a plugin written then keeps compiling).
template <class T>
constexpr bool takesCheckedParams = std::is_constructible_v<T, const CheckedParams &, Host &>;
template <class T>
constexpr bool takesRawParams = std::is_constructible_v<T, const Params &, Host &>;

// The plugin's instance, made from settings checked against its table first.
template <class T>
std::unique_ptr<T> makePlugin(const Params &raw, Host &host) {
    static_assert(takesCheckedParams<T> || takesRawParams<T>,
                  "a plugin class needs a constructor T(const binocle::sdk::CheckedParams &, binocle::sdk::Host &)");
    const CheckedParams checked(raw, paramsOf<T>(), pluginNameOf<T>());
    if constexpr (takesCheckedParams<T>)
        return std::make_unique<T>(checked, host);
    else
        return std::make_unique<T>(raw, host);
}

template <class Inst, class Handle>
binocle_result create(const binocle_param *params, int32_t n, const binocle_host *host, Handle **out) noexcept {
    if (!out) return BINOCLE_ERR_INVALID_ARGUMENT;
    *out = nullptr;
    return guard(createError(), [&] {
        auto inst = std::make_unique<Inst>(host);
        inst->impl = makePlugin<typename Inst::Impl>(Params(params, n), inst->hostView);
        *out = reinterpret_cast<Handle *>(inst.release());
    });
}

template <class Inst, class Handle>
void destroy(Handle *h) noexcept {
    try { delete reinterpret_cast<Inst *>(h); } catch (...) {}
}

template <class Inst, class Handle>
const char *lastError(Handle *h) noexcept {
    if (!h) return createError().c_str();
    return reinterpret_cast<Inst *>(h)->error.c_str();
}

template <class T, class Handle>
Instance<T> &inst(Handle *h) {
    return *reinterpret_cast<Instance<T> *>(h);
}

// Matcher instances keep the list of extras they last handed out.
template <class T>
struct MatcherInstance : Instance<T> {
    using Instance<T>::Instance;
    std::vector<binocle_named_image> extras;
};

// Source instances also keep the frames they have lent.
template <class T>
struct SourceInstance : Instance<T> {
    using Instance<T>::Instance;
    struct Lent {
        std::unique_ptr<Frame> frame;
        std::vector<binocle_named_image> extras;
    };
    std::mutex lentMutex;
    std::map<uint64_t, Lent> lent;
    uint64_t nextId = 1;
    std::string calibration, statistics;
    bool calibrationRead = false;
};

template <class T>
SourceInstance<T> &src(binocle_source *h) {
    return *reinterpret_cast<SourceInstance<T> *>(h);
}

template <class T>
binocle_result sourceGrab(binocle_source *h, int32_t timeout_ms, binocle_stereo_frame *out) noexcept {
    auto &s = src<T>(h);
    return guard(s.error, [&] {
        if (!out) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "grab: frame is NULL");
        std::unique_ptr<Frame> f = s.impl->grab(timeout_ms);
        if (!f) throw Error(BINOCLE_ERR_INTERNAL, "grab returned no frame");
        typename SourceInstance<T>::Lent lent;
        for (auto &e : f->extras) lent.extras.push_back(binocle_named_image{e.first.c_str(), e.second});
        binocle_stereo_frame v{};
        v.struct_size = out->struct_size < sizeof(v) ? out->struct_size : static_cast<uint32_t>(sizeof(v));
        v.sequence = f->sequence;
        v.timestamp_left_ns = f->timestamp_left_ns;
        v.timestamp_right_ns = f->timestamp_right_ns;
        v.left = f->left;
        v.right = f->right;
        v.extras = lent.extras.empty() ? nullptr : lent.extras.data();
        v.extra_count = static_cast<int32_t>(lent.extras.size());
        v.metadata = f->metadata.empty() ? nullptr : f->metadata.c_str();
        lent.frame = std::move(f);
        {
            std::lock_guard<std::mutex> lock(s.lentMutex);
            v.frame_id = s.nextId++;
            s.lent.emplace(v.frame_id, std::move(lent));
        }
        std::memcpy(out, &v, v.struct_size ? v.struct_size : sizeof(v));
    });
}

template <class T>
binocle_result sourceRelease(binocle_source *h, uint64_t id) noexcept {
    auto &s = src<T>(h);
    return guard(s.error, [&] {
        typename SourceInstance<T>::Lent gone;
        {
            std::lock_guard<std::mutex> lock(s.lentMutex);
            auto it = s.lent.find(id);
            if (it == s.lent.end()) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "release of a frame that is not lent: id " + std::to_string(id));
            gone = std::move(it->second);
            s.lent.erase(it);
        }
        // `gone` is destroyed here, outside the lock: onRelease runs now.
    });
}

template <class T>
binocle_result sourceStart(binocle_source *h) noexcept {
    auto &s = src<T>(h);
    return guard(s.error, [&] { s.impl->start(); });
}

template <class T>
binocle_result sourceStop(binocle_source *h) noexcept {
    auto &s = src<T>(h);
    return guard(s.error, [&] { s.impl->stop(); });
}

template <class T>
binocle_result sourceCalibration(binocle_source *h, const char **yaml) noexcept {
    auto &s = src<T>(h);
    return guard(s.error, [&] {
        if (!yaml) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "calibration: yaml is NULL");
        if (!s.calibrationRead) {
            s.calibration = s.impl->calibration();
            s.calibrationRead = true;
        }
        *yaml = s.calibration.empty() ? nullptr : s.calibration.c_str();
    });
}

template <class T>
binocle_result sourceStatistics(binocle_source *h, const char **yaml) noexcept {
    auto &s = src<T>(h);
    return guard(s.error, [&] {
        if (!yaml) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "statistics: yaml is NULL");
        s.statistics = s.impl->statistics();
        *yaml = s.statistics.empty() ? nullptr : s.statistics.c_str();
    });
}

template <class T>
binocle_result sourceEnumerate(const binocle_host *host, const char **yaml) noexcept {
    static thread_local std::string text;
    return guard(createError(), [&] {
        if (!yaml) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "enumerate_devices: yaml is NULL");
        Host hv(host);
        text = T::enumerateDevices(hv);
        *yaml = text.c_str();
    });
}

template <class T>
binocle_result matcherCompute(binocle_matcher *h, const binocle_image *l, const binocle_image *r,
                              binocle_image *d) noexcept {
    auto &s = inst<T>(h);
    return guard(s.error, [&] {
        if (!l || !r || !d) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "compute: NULL image");
        s.impl->compute(*l, *r, *d);
    });
}

template <class T>
binocle_result matcherExtras(binocle_matcher *h, const binocle_named_image **extras, int32_t *count) noexcept {
    auto &s = *reinterpret_cast<MatcherInstance<T> *>(h);
    return guard(s.error, [&] {
        if (!extras || !count) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "extras: NULL argument");
        s.extras = s.impl->extras();
        *extras = s.extras.empty() ? nullptr : s.extras.data();
        *count = static_cast<int32_t>(s.extras.size());
    });
}

template <class T>
binocle_result matcherRange(binocle_matcher *h, int32_t *mn, int32_t *num) noexcept {
    auto &s = inst<T>(h);
    return guard(s.error, [&] {
        auto r = s.impl->disparityRange();
        if (mn) *mn = r.first;
        if (num) *num = r.second;
    });
}

template <class T>
binocle_result transformApply(binocle_cloud_transform *h, binocle_cloud *c) noexcept {
    auto &s = inst<T>(h);
    return guard(s.error, [&] {
        if (!c) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "apply: cloud is NULL");
        s.impl->apply(*c);
    });
}

template <class T>
binocle_result evaluatorEvaluate(binocle_evaluator *h, const binocle_eval_input *in) noexcept {
    auto &s = inst<T>(h);
    return guard(s.error, [&] {
        if (!in) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "evaluate: input is NULL");
        s.impl->evaluate(*in);
    });
}

template <class T>
binocle_result evaluatorFinish(binocle_evaluator *h) noexcept {
    auto &s = inst<T>(h);
    return guard(s.error, [&] { s.impl->finish(); });
}

inline binocle_plugin_header header(uint32_t size, int32_t kind, const char *name, const char *version,
                                    const char *description) {
    return binocle_plugin_header{size, BINOCLE_ABI_VERSION, BINOCLE_API_VERSION, kind, name, version, description};
}

// A kind's table with the entries every kind's table begins with filled in: the header,
// T's settings, and create, destroy and last_error on `Wrapper` behind handles `Handle`.
template <class Table, class T, class Wrapper, class Handle>
Table tableOf(int32_t kind, const char *name, const char *version, const char *description) {
    Table t{};
    t.header = header(sizeof(t), kind, name, version, description);
    pluginNameOf<T>() = name ? name : "";
    t.params = paramsOf<T>().data();
    t.param_count = static_cast<int32_t>(paramsOf<T>().size());
    t.create = &create<Wrapper, Handle>;
    t.destroy = &destroy<Wrapper, Handle>;
    t.last_error = &lastError<Wrapper, Handle>;
    return t;
}

// The table of plugin class T, made once: tableOf()'s entries, then the kind's own,
// which `calls` fills in.
template <class Table, class T, class Wrapper, class Handle, class Calls>
const Table *onceTable(int32_t kind, const char *name, const char *version, const char *description, Calls calls) {
    static const Table table = [&] {
        auto t = tableOf<Table, T, Wrapper, Handle>(kind, name, version, description);
        calls(t);
        return t;
    }();
    return &table;
}

template <class T>
const binocle_source_api *sourceTable(const char *name, const char *version, const char *description) {
    return onceTable<binocle_source_api, T, SourceInstance<T>, binocle_source>(
        BINOCLE_KIND_STEREO_SOURCE, name, version, description, [](binocle_source_api &t) {
            t.start = &sourceStart<T>;
            t.stop = &sourceStop<T>;
            t.grab = &sourceGrab<T>;
            t.release_frame = &sourceRelease<T>;
            t.calibration = &sourceCalibration<T>;
            t.statistics = &sourceStatistics<T>;
            t.enumerate_devices = &sourceEnumerate<T>;
        });
}

template <class T>
const binocle_matcher_api *matcherTable(const char *name, const char *version, const char *description) {
    return onceTable<binocle_matcher_api, T, MatcherInstance<T>, binocle_matcher>(
        BINOCLE_KIND_MATCHER, name, version, description, [](binocle_matcher_api &t) {
            t.compute = &matcherCompute<T>;
            t.disparity_range = &matcherRange<T>;
            t.extras = &matcherExtras<T>;
        });
}

template <class T>
const binocle_cloud_transform_api *transformTable(const char *name, const char *version, const char *description) {
    return onceTable<binocle_cloud_transform_api, T, Instance<T>, binocle_cloud_transform>(
        BINOCLE_KIND_CLOUD_TRANSFORM, name, version, description,
        [](binocle_cloud_transform_api &t) { t.apply = &transformApply<T>; });
}

template <class T>
const binocle_evaluator_api *evaluatorTable(const char *name, const char *version, const char *description) {
    return onceTable<binocle_evaluator_api, T, Instance<T>, binocle_evaluator>(
        BINOCLE_KIND_EVALUATOR, name, version, description, [](binocle_evaluator_api &t) {
            t.evaluate = &evaluatorEvaluate<T>;
            t.finish = &evaluatorFinish<T>;
        });
}

} // namespace detail
} // namespace binocle::sdk

// The init symbol: returns the plugin's table whatever the host asks, so that the host
// can name both versions when they differ.
#define BINOCLE_DETAIL_EXPORT(TABLE_EXPR)                                                             \
    extern "C" BINOCLE_PLUGIN_EXPORT const binocle_plugin_header *binocle_plugin_init(uint32_t, uint32_t) { \
        try {                                                                                         \
            return &(TABLE_EXPR)->header;                                                             \
        } catch (...) {                                                                               \
            return nullptr;                                                                           \
        }                                                                                             \
    }

#define BINOCLE_EXPORT_SOURCE(CLASS, NAME, VERSION, DESCRIPTION) \
    BINOCLE_DETAIL_EXPORT(::binocle::sdk::detail::sourceTable<CLASS>(NAME, VERSION, DESCRIPTION))
#define BINOCLE_EXPORT_MATCHER(CLASS, NAME, VERSION, DESCRIPTION) \
    BINOCLE_DETAIL_EXPORT(::binocle::sdk::detail::matcherTable<CLASS>(NAME, VERSION, DESCRIPTION))
#define BINOCLE_EXPORT_CLOUD_TRANSFORM(CLASS, NAME, VERSION, DESCRIPTION) \
    BINOCLE_DETAIL_EXPORT(::binocle::sdk::detail::transformTable<CLASS>(NAME, VERSION, DESCRIPTION))
#define BINOCLE_EXPORT_EVALUATOR(CLASS, NAME, VERSION, DESCRIPTION) \
    BINOCLE_DETAIL_EXPORT(::binocle::sdk::detail::evaluatorTable<CLASS>(NAME, VERSION, DESCRIPTION))
