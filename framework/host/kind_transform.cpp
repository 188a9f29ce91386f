// SPDX-License-Identifier: MIT
// The cloud transform kind: its descriptor, its instance in this process, behind a proxy,
// and in the helper process, and the CloudTransform wrapper.
#include "host/kind_transform.hpp"

#include "host/instance_support.hpp"
#include "host/isolated_side.hpp"
#include "host/kind_transform_messages.hpp"
#include "host/isolation.hpp"
#include "host/plugin_kinds.hpp"

namespace binocle {

namespace {

enum TransformOp : uint32_t { kApply = wire::kFirstKindOp };

} // namespace

// What a transform instance does, wherever it runs.
class CloudTransform::Impl : public InstanceImpl {
public:
    virtual void apply(binocle_cloud &cloud) = 0;
};

namespace {

class InProcessTransform : public CloudTransform::Impl, Created<binocle_cloud_transform_api, binocle_cloud_transform> {
public:
    InProcessTransform(const PluginRecord &record, const ParamValues &params, const std::shared_ptr<binocle_host> &host)
        : Created(record, params, host.get()) {}
    void apply(binocle_cloud &cloud) override {
        const binocle_cloud before = cloud;
        const int32_t rc = api_->apply(handle_, &cloud);
        if (rc != BINOCLE_OK) failed("apply", rc);
        if (cloud.count < 0 || cloud.count > before.count || cloud.xyz != before.xyz || cloud.rgb != before.rgb ||
            cloud.pixel != before.pixel || (cloud.frame != BINOCLE_FRAME_CAMERA && cloud.frame != BINOCLE_FRAME_GROUND)) {
            const int64_t count = cloud.count;
            cloud = before;
            failCall(record_, "apply", BINOCLE_ERR_INTERNAL,
                     ("returned a garbage cloud (count " + std::to_string(count) + " of " + std::to_string(before.count) +
                      ", arrays or frame changed)")
                         .c_str());
        }
    }
};

class TransformProxy : public Proxied<CloudTransform::Impl> {
public:
    TransformProxy(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation,
                   const std::shared_ptr<binocle_host> &host)
        : Proxied(record, params, isolation, host), shared_(record.name, 0) {}
    // The cloud's arrays cross in shared memory and come back rewritten; after a restart
    // the cloud of that frame is dropped (count 0). The helper's wrapper checked the cloud.
    void apply(binocle_cloud &cloud) override {
        wire::Layout layout;
        wire::Writer w;
        wire::putCloud(w, layout, cloud);
        const bool done = guarded([&] {
            uint8_t *base = shared_.reserve(layout.bytes());
            layout.copyInto(base);
            Reply r = call(kApply, w.data(), &shared_);
            const wire::AppliedCloud a = wire::get<wire::AppliedCloud>(r.payload);
            if (a.count < 0 || a.count > cloud.count) throw Error("malformed cloud from the plugin helper");
            const uint64_t n = static_cast<uint64_t>(a.count);
            const wire::Region region = shared_.region();
            // Back into the host's own arrays: the transform may have compacted them.
            std::memcpy(cloud.xyz, wire::arrayAt(a.xyz, 3 * n * sizeof(float), region), 3 * n * sizeof(float));
            if (cloud.rgb) std::memcpy(cloud.rgb, wire::arrayAt(a.rgb, 3 * n, region), 3 * n);
            if (cloud.pixel) std::memcpy(cloud.pixel, wire::arrayAt(a.pixel, n * sizeof(int32_t), region), n * sizeof(int32_t));
            cloud.count = a.count;
            cloud.frame = a.frame;
        });
        if (!done) cloud.count = 0;
    }

private:
    SharedRegion shared_;
};

class ServedTransform : public ServedThrough<CloudTransform> {
public:
    using ServedThrough::ServedThrough;
    void call(uint32_t op, wire::Reader &r, wire::Region m, wire::Writer &out) override {
        if (op != kApply) throw Error("helper: unknown transform request " + std::to_string(op));
        binocle_cloud c = wire::getCloud(r, m);
        instance_.apply(c); // the wrapper refuses a garbage cloud
        const auto offset = [&](const void *p) {
            return p ? static_cast<uint64_t>(static_cast<const uint8_t *>(p) - m.base) : 0;
        };
        wire::put(out, wire::AppliedCloud{c.count, c.frame, offset(c.xyz), offset(c.rgb), offset(c.pixel)});
    }
};

} // namespace

// ---- The wrapper ------------------------------------------------------------------------------

CloudTransform::CloudTransform(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation)
    : PluginInstanceBase(record), impl_(choose<Impl, InProcessTransform, TransformProxy>(record_, params, isolation)) {}

CloudTransform::~CloudTransform() = default;

void CloudTransform::apply(binocle_cloud &cloud) { impl_->apply(cloud); }

// ---- The descriptor ---------------------------------------------------------------------------

const PluginKind &transformKind() {
    using T = binocle_cloud_transform_api;
    static const PluginKind kind = tableKind<T>(
        BINOCLE_KIND_CLOUD_TRANSFORM, "transform", "transforms", PluginKind::InRig::List,
        {{1, BINOCLE_END_OF(T, apply), "apply"}},
        {{"apply", offsetof(T, apply), true, kApply}},
        "this frame's cloud is dropped", &serveAs<ServedTransform>);
    return kind;
}

} // namespace binocle
