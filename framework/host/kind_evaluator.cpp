// SPDX-License-Identifier: MIT
// The evaluator kind: its descriptor, its instance in this process, behind a proxy, and
// in the helper process, and the Evaluator wrapper.
#include "host/kind_evaluator.hpp"

#include "host/instance_support.hpp"
#include "host/isolated_side.hpp"
#include "host/kind_evaluator_messages.hpp"
#include "host/isolation.hpp"
#include "host/plugin_kinds.hpp"

namespace binocle {

namespace {

enum EvaluatorOp : uint32_t { kEvaluate = wire::kFirstKindOp, kFinish };

} // namespace

// What an evaluator instance does, wherever it runs.
class Evaluator::Impl : public InstanceImpl {
public:
    virtual void evaluate(const binocle_eval_input &input) = 0;
    virtual void finish() = 0;
};

namespace {

class InProcessEvaluator : public Evaluator::Impl, Created<binocle_evaluator_api, binocle_evaluator> {
public:
    InProcessEvaluator(const PluginRecord &record, const ParamValues &params, const std::shared_ptr<binocle_host> &host)
        : Created(record, params, host.get()) {}
    void evaluate(const binocle_eval_input &input) override {
        const int32_t rc = api_->evaluate(handle_, &input);
        if (rc != BINOCLE_OK) failed("evaluate", rc);
    }
    void finish() override {
        if (!api_->finish) return;
        const int32_t rc = api_->finish(handle_);
        if (rc != BINOCLE_OK) failed("finish", rc);
    }
};

// Frame, rectified images, disparity and cloud cross in shared memory; the figures the
// plugin reports come back through the instance's binocle_host during the call. A
// restart loses the figures of that frame and whatever the plugin had gathered.
class EvaluatorProxy : public Proxied<Evaluator::Impl> {
public:
    EvaluatorProxy(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation,
                   const std::shared_ptr<binocle_host> &host)
        : Proxied(record, params, isolation, host), shared_(record.name, 0) {}
    void evaluate(const binocle_eval_input &in) override {
        // The calibration and the rig change rarely: sent again only when they did, or to
        // a helper process that has not had them.
        const bool fresh = sentGeneration_ != generation();
        const bool sendCalibration = fresh || !calibration_.same(in.calibration_yaml);
        const bool sendRig = fresh || !rig_.same(in.rig_yaml);
        wire::Layout layout;
        wire::Writer w;
        wire::putEvaluate(w, layout, in, sendCalibration, sendRig);
        if (sendCalibration) calibration_.keep(in.calibration_yaml);
        if (sendRig) rig_.keep(in.rig_yaml);
        guarded([&] {
            layout.copyInto(shared_.reserve(layout.bytes()));
            call(kEvaluate, w.data(), &shared_);
            sentGeneration_ = generation();
        }); // after a restart the frame has no figures from this evaluator (a warning said so)
    }
    void finish() override {
        guarded([&] { call(kFinish); });
    }

private:
    // A text the helper process has (NULL and "" differ).
    struct Sent {
        bool isNull = false;
        std::string text;
        bool same(const char *t) const { return (t == nullptr) == isNull && (!t || text == t); }
        void keep(const char *t) {
            isNull = t == nullptr;
            text = t ? t : "";
        }
    };
    SharedRegion shared_;
    Sent calibration_, rig_;
    uint64_t sentGeneration_ = 0; // the helper process that has them
};

class ServedEvaluator : public ServedInstance {
public:
    ServedEvaluator(const PluginRecord &record, const ParamValues &params, HostSink sink)
        : evaluator_(record, params, std::move(sink)) {}
    void call(uint32_t op, wire::Reader &r, wire::Region m, wire::Writer &) override {
        if (op == kFinish) return evaluator_.finish();
        if (op != kEvaluate) throw Error("helper: unknown evaluator request " + std::to_string(op));
        wire::EvaluateInput input;
        wire::getEvaluate(r, m, texts_, input);
        evaluator_.evaluate(input.in);
    }

private:
    Evaluator evaluator_;
    wire::EvaluateTexts texts_; // the calibration and rig last sent
};

} // namespace

// ---- What crosses to the helper process (kind_evaluator_messages.hpp) ----------------------

namespace wire {

void putEvaluate(Writer &w, Layout &layout, const binocle_eval_input &in, bool sendCalibration, bool sendRig) {
    w.put<uint8_t>(in.frame != nullptr);
    if (in.frame) putFrame(w, layout, *in.frame);
    for (const binocle_image *im : {in.rectified_left, in.rectified_right, in.disparity}) {
        w.put<uint8_t>(im != nullptr);
        if (im) putImage(w, layout.place(*im));
    }
    w.put<uint8_t>(in.cloud != nullptr);
    if (in.cloud) putCloud(w, layout, *in.cloud);
    // A text the helper process has already: a byte that says "the same as before".
    w.put<uint8_t>(!sendCalibration);
    if (sendCalibration) w.cstr(in.calibration_yaml);
    w.put<uint8_t>(!sendRig);
    if (sendRig) w.cstr(in.rig_yaml);
    w.cstr(in.output_dir);
    // What the host knows of the matcher's search and the ground pose (appended members).
    w.put<int32_t>(in.min_disparity).put<int32_t>(in.num_disparities).put<int32_t>(in.ground_pose_known);
    w.put<double>(in.camera_height_mm).put<double>(in.inclination_deg);
    // The matcher's planes (appended members).
    putNamedImages(w, layout, in.disparity_extras, in.disparity_extras ? in.disparity_extra_count : 0);
}

void getEvaluate(Reader &r, Region region, EvaluateTexts &texts, EvaluateInput &out) {
    const bool hasFrame = r.get<uint8_t>() != 0;
    if (hasFrame) out.frame = getFrame(r, region, out.frameTexts);
    bool has[3];
    for (int i = 0; i < 3; ++i) {
        has[i] = r.get<uint8_t>() != 0;
        if (has[i]) out.images[i] = getImage(r, region);
    }
    const bool hasCloud = r.get<uint8_t>() != 0;
    if (hasCloud) out.cloud = getCloud(r, region);
    for (auto *text : {&texts.calibration, &texts.rig})
        if (r.get<uint8_t>() == 0) *text = r.cstr(); // else: the same as before
    out.output = r.cstr();
    binocle_eval_input &in = out.in;
    in = binocle_eval_input{};
    in.min_disparity = r.get<int32_t>();
    in.num_disparities = r.get<int32_t>();
    in.ground_pose_known = r.get<int32_t>();
    in.camera_height_mm = r.get<double>();
    in.inclination_deg = r.get<double>();
    getNamedImages(r, region, out.disparityExtras);
    in.disparity_extras = out.disparityExtras.images.empty() ? nullptr : out.disparityExtras.images.data();
    in.disparity_extra_count = static_cast<int32_t>(out.disparityExtras.images.size());
    in.struct_size = sizeof in;
    in.frame = hasFrame ? &out.frame : nullptr;
    in.rectified_left = has[0] ? &out.images[0] : nullptr;
    in.rectified_right = has[1] ? &out.images[1] : nullptr;
    in.disparity = has[2] ? &out.images[2] : nullptr;
    in.cloud = hasCloud ? &out.cloud : nullptr;
    in.calibration_yaml = texts.calibration.first ? texts.calibration.second.c_str() : nullptr;
    in.rig_yaml = texts.rig.first ? texts.rig.second.c_str() : nullptr;
    in.output_dir = out.output.first ? out.output.second.c_str() : nullptr;
}

} // namespace wire

// ---- The wrapper ------------------------------------------------------------------------------

Evaluator::Evaluator(const PluginRecord &record, const ParamValues &params, HostSink sink, const IsolationOptions &isolation)
    : PluginInstanceBase(record) {
    setSink(std::move(sink)); // before create: what it logs goes there already
    impl_ = choose<Impl, InProcessEvaluator, EvaluatorProxy>(record_, params, isolation);
}

Evaluator::~Evaluator() = default;

void Evaluator::evaluate(const binocle_eval_input &input) { impl_->evaluate(input); }

void Evaluator::finish() { impl_->finish(); }

// ---- The descriptor ---------------------------------------------------------------------------

const PluginKind &evaluatorKind() {
    using T = binocle_evaluator_api;
    static const PluginKind kind = tableKind<T>(
        BINOCLE_KIND_EVALUATOR, "evaluator", "evaluators", PluginKind::InRig::List,
        {{1, BINOCLE_END_OF(T, finish), "finish"}},
        {{"evaluate", offsetof(T, evaluate), true, kEvaluate}, {"finish", offsetof(T, finish), false, kFinish}},
        "this frame has no figures from it, and its totals start again", &serveAs<ServedEvaluator>);
    return kind;
}

} // namespace binocle
