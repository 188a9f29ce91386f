// SPDX-License-Identifier: MIT
// `disparity` evaluator: bad-pixel rates, end-point error and density of a disparity map
// against the ground truth the source attaches to the frame (simulated rig, Middlebury,
// KITTI, any "gt_disparity" plane).
#include <binocle/plugin.hpp>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace {

using binocle::sdk::Error;
using binocle::sdk::Param;

const binocle_image *findExtra(const binocle_stereo_frame &f, const char *name) {
    for (int32_t i = 0; i < f.extra_count; ++i)
        if (f.extras[i].name && std::strcmp(f.extras[i].name, name) == 0) return &f.extras[i].image;
    return nullptr;
}

template <class T>
const T &at(const binocle_image &im, int u, int v) {
    return reinterpret_cast<const T *>(static_cast<const uint8_t *>(im.data) + static_cast<size_t>(v) * im.stride_bytes)[u];
}

// Counts over the pixels where the ground truth is known.
struct Tally {
    double known = 0;     // ground truth known
    double matched = 0;   // ground truth known and the matcher gave a disparity
    double bad[3] = {0, 0, 0};
    double abs_error = 0; // sum |d - gt| over matched
    void add(const Tally &o) {
        known += o.known;
        matched += o.matched;
        for (int i = 0; i < 3; ++i) bad[i] += o.bad[i];
        abs_error += o.abs_error;
    }
};

class DisparityEvaluator : public binocle::sdk::Evaluator {
public:
    static std::vector<binocle_param_desc> parameters() {
        return {
            Param::real("threshold_1_px", "1").min(0).unit("px").help("first bad-pixel threshold"),
            Param::real("threshold_2_px", "2").min(0).unit("px").help("second bad-pixel threshold"),
            Param::real("threshold_3_px", "4").min(0).unit("px").help("third bad-pixel threshold"),
            Param::choice("invalid_pixels", "excluded", "excluded|bad")
                .help("matcher holes where the truth is known: left out of the error rates (density tells them), or counted as bad"),
            Param::boolean("require_ground_truth", true)
                .help("fail when a frame carries no gt_disparity plane (false: report nothing for it)"),
        };
    }

    DisparityEvaluator(const binocle::sdk::Params &p, binocle::sdk::Host &host)
        : host_(host), holesAreBad_(p.string("invalid_pixels") == "bad"), require_(p.boolean("require_ground_truth")) {
        thresholds_[0] = p.real("threshold_1_px");
        thresholds_[1] = p.real("threshold_2_px");
        thresholds_[2] = p.real("threshold_3_px");
    }

    void evaluate(const binocle_eval_input &in) override {
        if (!in.frame || !in.disparity) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "disparity evaluator: no frame or disparity");
        const binocle_image *gt = findExtra(*in.frame, "gt_disparity");
        if (!gt) {
            if (require_)
                throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                            "disparity evaluator: frame " + std::to_string(in.frame->sequence) +
                                " carries no 'gt_disparity' plane (the source gives no ground truth; "
                                "set require_ground_truth: false to skip such frames)");
            return;
        }
        const binocle_image &d = *in.disparity;
        if (gt->format != BINOCLE_PIXEL_FLOAT32 || d.format != BINOCLE_PIXEL_FLOAT32 || gt->width != d.width || gt->height != d.height)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                        "disparity evaluator: gt_disparity is " + std::to_string(gt->width) + "x" + std::to_string(gt->height) +
                            " (format " + std::to_string(gt->format) + "), the disparity map " + std::to_string(d.width) + "x" +
                            std::to_string(d.height) + ": expected the same size, both FLOAT32");
        const binocle_image *valid = findExtra(*in.frame, "gt_valid");
        Tally t;
        for (int v = 0; v < d.height; ++v)
            for (int u = 0; u < d.width; ++u) {
                const float g = at<float>(*gt, u, v);
                if (!(g > 0) || !std::isfinite(g)) continue;
                if (valid && valid->format == BINOCLE_PIXEL_GRAY8 && at<uint8_t>(*valid, u, v) == 0) continue;
                t.known += 1;
                const float x = at<float>(d, u, v);
                if (!(x > 0) || !std::isfinite(x)) {
                    if (holesAreBad_)
                        for (double &b : t.bad) b += 1;
                    continue;
                }
                t.matched += 1;
                const double e = std::fabs(x - g);
                t.abs_error += e;
                for (int i = 0; i < 3; ++i)
                    if (e > thresholds_[i]) t.bad[i] += 1;
            }
        report(t);
        total_.add(t);
        ++frames_;
    }

    void finish() override {
        if (frames_ == 0) return;
        host_.metric("frames", frames_);
        report(total_);
    }

private:
    void report(const Tally &t) {
        const double base = holesAreBad_ ? t.known : t.matched;
        for (int i = 0; i < 3; ++i) {
            char name[64];
            std::snprintf(name, sizeof name, "bad_%gpx_percent", thresholds_[i]);
            host_.metric(name, base > 0 ? 100.0 * t.bad[i] / base : NAN, "%");
        }
        host_.metric("mean_epe_px", t.matched > 0 ? t.abs_error / t.matched : NAN, "px");
        host_.metric("density_percent", t.known > 0 ? 100.0 * t.matched / t.known : NAN, "%");
        host_.metric("ground_truth_pixels", t.known);
    }

    binocle::sdk::Host &host_;
    double thresholds_[3];
    bool holesAreBad_;
    bool require_;
    Tally total_;
    int frames_ = 0;
};

} // namespace

BINOCLE_EXPORT_EVALUATOR(DisparityEvaluator, "disparity", "1.0.0",
                         "Bad-pixel rates, mean end-point error and density against the source's ground-truth disparity")
