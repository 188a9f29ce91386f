// SPDX-License-Identifier: MIT
// Conformance cases of an evaluator: evaluate on read-only guarded inputs, determinism.
#include "conformance/kit.hpp"

#include <cstring>

namespace binocle::conformance {

namespace {

// Scores one synthetic frame (constant disparity 8 on a textured pair, with ground truth)
// on read-only guarded inputs; returns the figures it reported.
std::vector<std::pair<std::string, double>> evaluated(const binocle_evaluator_api *api, binocle_evaluator *h, HostBlock &host) {
    constexpr int w = 160, hgt = 120;
    cv::Mat left, right;
    texturedPair(left, right, w, hgt, CV_8UC1);
    Guarded l(left.total()), r(right.total()), d(left.total() * 4), gt(left.total() * 4);
    std::memcpy(l.data(), left.data, left.total());
    std::memcpy(r.data(), right.data, right.total());
    std::fill_n(reinterpret_cast<float *>(d.data()), left.total(), 8.0f);
    std::fill_n(reinterpret_cast<float *>(gt.data()), left.total(), 8.0f);
    l.readOnly();
    r.readOnly();
    d.readOnly();
    gt.readOnly();
    binocle_named_image extra{"gt_disparity", imageOf(gt.data(), w, hgt, BINOCLE_PIXEL_FLOAT32, 4)};
    binocle_stereo_frame frame{};
    frame.struct_size = sizeof frame;
    frame.left = imageOf(l.data(), w, hgt, BINOCLE_PIXEL_GRAY8, 1);
    frame.right = imageOf(r.data(), w, hgt, BINOCLE_PIXEL_GRAY8, 1);
    frame.extras = &extra;
    frame.extra_count = 1;
    binocle_image disparity = imageOf(d.data(), w, hgt, BINOCLE_PIXEL_FLOAT32, 4);
    GuardedCloud cloud(500);
    binocle_eval_input in{};
    in.struct_size = sizeof in;
    in.frame = &frame;
    in.rectified_left = &frame.left;
    in.rectified_right = &frame.right;
    in.disparity = &disparity;
    in.cloud = &cloud.cloud;
    in.rig_yaml = "name: plugin-check\n";
    host.recorder.metrics.clear();
    const int32_t rc = api->evaluate(h, &in);
    expectMessage("evaluate", rc, api->last_error(h));
    if (rc != BINOCLE_OK) throw CaseFailure{std::string("\x01") + codeText(rc, api->last_error(h))};
    return host.recorder.metrics;
}

} // namespace

void evaluatorCases(Battery &b) {
    const Family<binocle_evaluator_api, binocle_evaluator> f(b);
    const auto *api = f.api;
    f.createDestroyCase();
    // An evaluator may refuse a synthetic frame (no calibration, no metadata): that is
    // fine when it says why with a code; the determinism case then has nothing to compare.
    auto evaluateOrRefusal = [&](binocle_evaluator *h, HostBlock &host, std::string &refusal) {
        try {
            return evaluated(api, h, host);
        } catch (const CaseFailure &failure) {
            if (failure.message.empty() || failure.message[0] != '\x01') throw;
            refusal = failure.message.substr(1);
            return std::vector<std::pair<std::string, double>>{};
        }
    };
    f.instanceCase("evaluate_in_host_buffers", [&](binocle_evaluator *h, HostBlock &host) {
        std::string refusal;
        const auto figures = evaluateOrRefusal(h, host, refusal);
        if (api->finish) {
            const int32_t rc = api->finish(h);
            expectMessage("finish", rc, api->last_error(h));
        }
        if (!refusal.empty()) return pass("refused the synthetic frame with a code: " + refusal);
        return pass(std::to_string(figures.size()) + " figures reported; inputs left untouched");
    });
    b.run("determinism", [&] {
        HostBlock ha, hb;
        binocle_evaluator *a = f.create(ha);
        binocle_evaluator *c = f.create(hb);
        std::string refusal;
        const auto f1 = evaluateOrRefusal(a, ha, refusal);
        if (!refusal.empty()) return skip("the synthetic frame is refused (" + refusal + ")");
        const auto f2 = evaluateOrRefusal(c, hb, refusal);
        if (f1 != f2) fail("two instances with the same settings report different figures for the same frame");
        api->destroy(a);
        api->destroy(c);
        return pass(std::to_string(f1.size()) + " identical figures from two instances");
    });
}

} // namespace binocle::conformance
