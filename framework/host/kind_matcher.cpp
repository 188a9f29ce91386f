// SPDX-License-Identifier: MIT
// The matcher kind: its descriptor, its instance in this process, behind a proxy, and in
// the helper process, and the Matcher wrapper that checks what any of them computes.
#include "host/kind_matcher.hpp"

#include "host/instance_support.hpp"
#include "host/isolated_side.hpp"
#include "host/kind_matcher_messages.hpp"
#include "host/isolation.hpp"
#include "host/plugin_kinds.hpp"

#include <cmath>
#include <spdlog/spdlog.h>

namespace binocle {

namespace {

enum MatcherOp : uint32_t { kCompute = wire::kFirstKindOp, kRange };

} // namespace

// What a matcher instance does, wherever it runs.
class Matcher::Impl : public InstanceImpl {
public:
    // Into `disparity` (CV_32F, left's size), no clean-up of the values; `extras` becomes
    // the host's copy of the planes the plugin attached to it (matcher.h: extras).
    virtual void compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity,
                         std::vector<NamedPlane> &extras) = 0;
    virtual std::pair<int32_t, int32_t> disparityRange() = 0;
};

namespace {

// The most planes a matcher may attach to a disparity, and their most bytes: two FLOAT32
// planes' worth (the room isolation's shared memory keeps for them).
constexpr int32_t kMaxExtras = 64;
constexpr size_t kExtrasFloatPlanes = 2;

// A matcher's extras checked as matcher.h states them (named, unique, of the disparity's
// size, GRAY8, GRAY16 or FLOAT32), then copied: the plugin keeps its own until its next
// compute.
void copyExtras(const PluginRecord &record, const binocle_named_image *list, int32_t count, cv::Size size,
                std::vector<NamedPlane> &out) {
    auto refuse = [&](const std::string &why) { failCall(record, "extras", BINOCLE_ERR_INTERNAL, why.c_str()); };
    if (count < 0 || count > kMaxExtras || (count > 0 && !list))
        refuse("returned " + std::to_string(count) + " planes" + (list ? "" : " and no list") + ": expected 0 .. " +
               std::to_string(kMaxExtras) + ", with a list when more than 0");
    const size_t room = kExtrasFloatPlanes * size.area() * sizeof(float);
    size_t bytes = 0;
    for (int32_t i = 0; i < count; ++i) {
        const binocle_named_image &e = list[i];
        const std::string name = e.name ? e.name : "";
        const std::string what = "plane '" + name + "'";
        if (name.empty()) refuse("plane #" + std::to_string(i) + " has no name");
        for (const NamedPlane &p : out)
            if (p.name == name) refuse("two planes are named '" + name + "'");
        if (std::string why = checkImage(e.image, what.c_str()); !why.empty()) refuse(why);
        const int32_t f = e.image.format;
        if (f != BINOCLE_PIXEL_GRAY8 && f != BINOCLE_PIXEL_GRAY16 && f != BINOCLE_PIXEL_FLOAT32)
            refuse(what + " has pixel format " + std::to_string(f) + ": expected GRAY8 (" +
                   std::to_string(BINOCLE_PIXEL_GRAY8) + "), GRAY16 (" + std::to_string(BINOCLE_PIXEL_GRAY16) +
                   ") or FLOAT32 (" + std::to_string(BINOCLE_PIXEL_FLOAT32) + ")");
        if (e.image.width != size.width || e.image.height != size.height)
            refuse(what + " is " + std::to_string(e.image.width) + "x" + std::to_string(e.image.height) + ": expected " +
                   std::to_string(size.width) + "x" + std::to_string(size.height) + ", the disparity's size");
        bytes += static_cast<size_t>(e.image.width) * e.image.height * bytesPerPixel(f);
        if (bytes > room)
            refuse("planes up to '" + name + "' hold " + std::to_string(bytes) + " bytes: expected at most " +
                   std::to_string(room) + ", two FLOAT32 planes of the disparity's size");
        out.push_back({name, view(e.image).clone()});
    }
}

class InProcessMatcher : public Matcher::Impl, Created<binocle_matcher_api, binocle_matcher> {
public:
    InProcessMatcher(const PluginRecord &record, const ParamValues &params, const std::shared_ptr<binocle_host> &host)
        : Created(record, params, host.get()) {}
    void compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity, std::vector<NamedPlane> &extras) override {
        extras.clear();
        binocle_image l = wrap(left, formatOf(left)), r = wrap(right, formatOf(right));
        binocle_image d = wrap(disparity, BINOCLE_PIXEL_FLOAT32);
        const binocle_image expected = d;
        const int32_t rc = api_->compute(handle_, &l, &r, &d);
        if (rc != BINOCLE_OK) failed("compute", rc);
        if (d.data != expected.data || d.width != expected.width || d.height != expected.height ||
            d.format != expected.format || d.stride_bytes != expected.stride_bytes)
            failCall(record_, "compute", BINOCLE_ERR_INTERNAL,
                     "changed the host's disparity image description instead of writing into it");
        // Past an older plugin's struct_size the host's copy of the table reads NULL.
        if (!api_->extras) return;
        const binocle_named_image *list = nullptr;
        int32_t count = 0;
        const int32_t rx = api_->extras(handle_, &list, &count);
        if (rx != BINOCLE_OK) failed("extras", rx);
        copyExtras(record_, list, count, disparity.size(), extras);
    }
    std::pair<int32_t, int32_t> disparityRange() override {
        int32_t mn = 0, num = 0;
        if (!api_->disparity_range) return {0, 0};
        const int32_t rc = api_->disparity_range(handle_, &mn, &num);
        if (rc != BINOCLE_OK) failed("disparity_range", rc);
        return {mn, num};
    }
};

class MatcherProxy : public Proxied<Matcher::Impl> {
public:
    MatcherProxy(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation,
                 const std::shared_ptr<binocle_host> &host)
        : Proxied(record, params, isolation, host), shared_(record.name, 0) {}
    void compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity, std::vector<NamedPlane> &extras) override {
        extras.clear();
        wire::ComputeRequest c{left.cols, left.rows, left.type(), 0, 0};
        const size_t rowBytes = left.cols * left.elemSize();
        c.image_bytes = pageAligned(rowBytes * left.rows);
        const size_t dispBytes = pageAligned(static_cast<size_t>(left.cols) * left.rows * sizeof(float));
        // Room for the matcher's extras after the disparity: two FLOAT32 planes' worth (as
        // copyExtras allows), and each plane's alignment (pages never written cost nothing).
        c.extras_bytes = kExtrasFloatPlanes * dispBytes + kMaxExtras * 64;
        const bool done = guarded([&] {
            uint8_t *base = shared_.reserve(2 * c.image_bytes + dispBytes + c.extras_bytes);
            // The one copy of the pixels: into the shared mapping the helper process reads.
            left.copyTo(cv::Mat(left.size(), left.type(), base, rowBytes));
            right.copyTo(cv::Mat(right.size(), right.type(), base + c.image_bytes, rowBytes));
            wire::Writer w;
            wire::put(w, c);
            Reply reply = call(kCompute, w.data(), &shared_);
            cv::Mat(left.size(), CV_32F, base + 2 * c.image_bytes).copyTo(disparity);
            // The helper process checked them (copyExtras); copied out of the shared memory.
            wire::NamedImages planes;
            wire::getNamedImages(reply.payload, {base + 2 * c.image_bytes + dispBytes, c.extras_bytes}, planes);
            extras.clear();
            for (const binocle_named_image &p : planes.images) extras.push_back({p.name, view(p.image).clone()});
        });
        if (!done) {
            disparity.setTo(cv::Scalar(BINOCLE_INVALID_DISPARITY));
            extras.clear();
        }
    }
    std::pair<int32_t, int32_t> disparityRange() override {
        std::pair<int32_t, int32_t> range{0, 0};
        retried([&] {
            Reply r = call(kRange);
            range = wire::getRange(r.payload);
        });
        return range;
    }

private:
    SharedRegion shared_;
};

class ServedMatcher : public ServedThrough<Matcher> {
public:
    using ServedThrough::ServedThrough;
    void call(uint32_t op, wire::Reader &r, wire::Region m, wire::Writer &out) override {
        if (op == kRange) return wire::putRange(out, instance_.disparityRange());
        if (op != kCompute) throw Error("helper: unknown matcher request " + std::to_string(op));
        const wire::ComputeRequest c = wire::get<wire::ComputeRequest>(r);
        if (c.width <= 0 || c.height <= 0 || (c.cv_type != CV_8UC1 && c.cv_type != CV_8UC3))
            throw Error("helper: malformed compute request");
        const uint64_t row = static_cast<uint64_t>(c.width) * CV_ELEM_SIZE(c.cv_type);
        const uint64_t disparityBytes = static_cast<uint64_t>(c.width) * c.height * sizeof(float);
        const uint64_t extrasAt = 2 * c.image_bytes + pageAligned(disparityBytes);
        if (row * c.height > c.image_bytes || c.image_bytes > m.bytes / 2 || extrasAt > m.bytes ||
            c.extras_bytes > m.bytes - extrasAt)
            throw Error("helper: images do not fit the shared memory");
        cv::Mat left(c.height, c.width, c.cv_type, m.base), right(c.height, c.width, c.cv_type, m.base + c.image_bytes);
        cv::Mat disparity(c.height, c.width, CV_32F, m.base + 2 * c.image_bytes);
        disparity.setTo(cv::Scalar(BINOCLE_INVALID_DISPARITY));
        instance_.computeInto(left, right, disparity);
        // The extras after the disparity, described in the reply.
        std::vector<binocle_named_image> planes;
        for (const NamedPlane &p : instance_.extras()) planes.push_back({p.name.c_str(), wrap(p.image, formatOf(p.image))});
        wire::Layout layout;
        wire::putNamedImages(out, layout, planes.data(), static_cast<int32_t>(planes.size()));
        if (layout.bytes() > c.extras_bytes)
            throw Error("matcher '" + instance_.record().name + "': its extras need " + std::to_string(layout.bytes()) +
                        " bytes of shared memory, more than the " + std::to_string(c.extras_bytes) +
                        " the host gives them");
        layout.copyInto(m.base + extrasAt);
    }
};

} // namespace

// ---- The wrapper ------------------------------------------------------------------------------

Matcher::Matcher(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation)
    : PluginInstanceBase(record), impl_(choose<Impl, InProcessMatcher, MatcherProxy>(record_, params, isolation)) {}

Matcher::~Matcher() = default;

cv::Mat Matcher::compute(const cv::Mat &left, const cv::Mat &right) {
    cv::Mat disparity;
    compute(left, right, disparity);
    return disparity;
}

void Matcher::compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity) {
    if (left.size() != right.size() || left.type() != right.type())
        throw Error("matcher '" + record_.name + "': left and right images differ in size or type");
    disparity.create(left.size(), CV_32F);
    disparity.setTo(cv::Scalar(BINOCLE_INVALID_DISPARITY));
    impl_->compute(left, right, disparity, extras_); // each Impl clears extras_ first
    // A disparity is at most the image width; inf, NaN or 1e30 would become cloud points.
    const float limit = static_cast<float>(disparity.cols);
    uint64_t bad = 0;
    for (int y = 0; y < disparity.rows; ++y) {
        float *row = disparity.ptr<float>(y);
        for (int x = 0; x < disparity.cols; ++x)
            if (!std::isfinite(row[x]) || row[x] > limit) {
                row[x] = BINOCLE_INVALID_DISPARITY;
                ++bad;
            }
    }
    if (bad) {
        invalidated_ += bad;
        if (!warnedInvalid_)
            spdlog::warn("matcher plugin '{}': {} disparities not finite or beyond the image width ({} px) made invalid "
                         "(counted; further frames at debug level)", record_.name, bad, disparity.cols);
        else
            spdlog::debug("matcher plugin '{}': {} disparities not finite or absurd made invalid ({} so far)", record_.name,
                          bad, invalidated_);
        warnedInvalid_ = true;
    }
}

void Matcher::computeInto(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity) {
    impl_->compute(left, right, disparity, extras_); // each Impl clears extras_ first
}

std::pair<int32_t, int32_t> Matcher::disparityRange() { return impl_->disparityRange(); }

// ---- The descriptor ---------------------------------------------------------------------------

const PluginKind &matcherKind() {
    using T = binocle_matcher_api;
    static const PluginKind kind = tableKind<T>(
        BINOCLE_KIND_MATCHER, "matcher", "matcher", PluginKind::InRig::One,
        {{1, BINOCLE_END_OF(T, disparity_range), "disparity_range"}},
        {{"compute", offsetof(T, compute), true, kCompute},
         {"disparity_range", offsetof(T, disparity_range), false, kRange},
         {"extras", offsetof(T, extras), false, 0}}, // its planes travel in compute's reply
        "this frame has no disparity", &serveAs<ServedMatcher>);
    return kind;
}

} // namespace binocle
