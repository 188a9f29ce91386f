// SPDX-License-Identifier: MIT
// The evaluator kind: its descriptor, its instance in this process, behind a proxy, and
// in the helper process, and the Evaluator wrapper.
#include "host/kind_evaluator.hpp"

#include "host/instance_support.hpp"
#include "host/isolated_side.hpp"
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
