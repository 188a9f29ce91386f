// SPDX-License-Identifier: MIT
// `disparity` evaluator: the public benchmarks' own figures of a disparity map against the
// ground truth the source attaches to the frame (simulated rig, Middlebury, KITTI, any
// "gt_disparity" plane): Middlebury's bad-pixel rates, avgerr, rms and invalid share over
// the non-occluded and all pixels (as MiddEval3's evaldisp counts them), KITTI's D1 over
// noc and all (as its devkit counts it), and the density.
#include <binocle/numbers.hpp>
#include <binocle/plugin.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

using binocle::sdk::Error;
using binocle::sdk::Param;

const binocle_image *findPlane(const binocle_named_image *planes, int32_t count, const char *name) {
    for (int32_t i = 0; planes && i < count; ++i)
        if (planes[i].name && std::strcmp(planes[i].name, name) == 0) return &planes[i].image;
    return nullptr;
}

const binocle_image *findExtra(const binocle_stereo_frame &f, const char *name) {
    return findPlane(f.extras, f.extra_count, name);
}

template <class T>
const T &at(const binocle_image &im, int u, int v) {
    return reinterpret_cast<const T *>(static_cast<const uint8_t *>(im.data) + static_cast<size_t>(v) * im.stride_bytes)[u];
}

bool isHole(float d) { return !(d > 0) || !std::isfinite(d); }

// The counts of one region (non-occluded or all pixels with ground truth).
struct Tally {
    double n = 0;        // pixels scored: ground truth known (and non-occluded for that region)
    double invalid = 0;  // of those, holes of the matcher (no disparity)
    std::vector<double> bad; // per threshold: matched with |d - gt| > t, plus every hole
    double sum_abs = 0, sum_sq = 0; // over matched pixels
    double d1 = 0;       // KITTI: |e| > 3 px and |e| > 5 % of gt, on the hole-filled map
    double filled = 0;   // of the matched, those the matcher marked as filled in (disparity_filled)
    void add(const Tally &o) {
        n += o.n;
        filled += o.filled;
        invalid += o.invalid;
        bad.resize(o.bad.size(), 0);
        for (size_t i = 0; i < o.bad.size(); ++i) bad[i] += o.bad[i];
        sum_abs += o.sum_abs;
        sum_sq += o.sum_sq;
        d1 += o.d1;
    }
};

struct Frame {
    Tally all, nonocc;
    bool hasNonocc = false;
    bool hasFilled = false; // the matcher attached a disparity_filled plane
};

// The KITTI devkit's interpolateBackground (devkit_stereo_flow, io_disp.h): each run of
// holes between two matched pixels of a row takes the smaller (background) of the two,
// rows are extrapolated left and right from their outermost matched pixels, then columns
// up and down. D1 is scored on this map, as the devkit scores it.
std::vector<float> backgroundFilled(const binocle_image &d) {
    const int w = d.width, h = d.height;
    std::vector<float> out(static_cast<size_t>(w) * h);
    std::vector<char> ok(out.size());
    for (int v = 0; v < h; ++v)
        for (int u = 0; u < w; ++u) {
            const float x = at<float>(d, u, v);
            out[static_cast<size_t>(v) * w + u] = x;
            ok[static_cast<size_t>(v) * w + u] = !isHole(x);
        }
    auto D = [&](int u, int v) -> float & { return out[static_cast<size_t>(v) * w + u]; };
    auto valid = [&](int u, int v) { return ok[static_cast<size_t>(v) * w + u] != 0; };
    for (int v = 0; v < h; ++v) {
        int count = 0;
        for (int u = 0; u < w; ++u) {
            if (!valid(u, v)) {
                ++count;
                continue;
            }
            const int u1 = u - count, u2 = u - 1;
            if (count >= 1 && u1 > 0 && u2 < w - 1) {
                const float fill = std::min(D(u1 - 1, v), D(u2 + 1, v));
                for (int k = u1; k <= u2; ++k) D(k, v) = fill, ok[static_cast<size_t>(v) * w + k] = 1;
            }
            count = 0;
        }
        for (int u = 0; u < w; ++u)
            if (valid(u, v)) {
                for (int k = 0; k < u; ++k) D(k, v) = D(u, v), ok[static_cast<size_t>(v) * w + k] = 1;
                break;
            }
        for (int u = w - 1; u >= 0; --u)
            if (valid(u, v)) {
                for (int k = u + 1; k < w; ++k) D(k, v) = D(u, v), ok[static_cast<size_t>(v) * w + k] = 1;
                break;
            }
    }
    for (int u = 0; u < w; ++u) {
        for (int v = 0; v < h; ++v)
            if (valid(u, v)) {
                for (int k = 0; k < v; ++k) D(u, k) = D(u, v), ok[static_cast<size_t>(k) * w + u] = 1;
                break;
            }
        for (int v = h - 1; v >= 0; --v)
            if (valid(u, v)) {
                for (int k = v + 1; k < h; ++k) D(u, k) = D(u, v), ok[static_cast<size_t>(k) * w + u] = 1;
                break;
            }
    }
    for (size_t i = 0; i < out.size(); ++i)
        if (!ok[i]) out[i] = NAN; // a map without any matched pixel stays empty
    return out;
}

// "[0.5, 1, 2, 4]" or "- 0.5\n- 1" (the setting's YAML text) -> the thresholds; empty on a
// malformed list.
std::vector<double> parseThresholds(const std::string &text) {
    std::vector<double> out;
    std::string item;
    auto flush = [&]() {
        size_t a = item.find_first_not_of(" \t");
        if (a != std::string::npos && item[a] == '-' && a + 1 < item.size() && (item[a + 1] == ' ' || item[a + 1] == '\t'))
            ++a; // a block list's "- "
        a = item.find_first_not_of(" \t", a == std::string::npos ? item.size() : a);
        const size_t b = item.find_last_not_of(" \t\r");
        const std::string one = a == std::string::npos ? "" : item.substr(a, b - a + 1);
        item.clear();
        if (one.empty()) return true;
        double t = 0;
        // The SDK's one reader of numbers: decimal only ("0x1", "inf", "nan" refused).
        if (!binocle::sdk::parseDecimalReal(one, t) || !(t >= 0)) return false;
        out.push_back(t);
        return true;
    };
    for (char c : text + ",") {
        if (c == ',' || c == '\n' || c == '[' || c == ']') {
            if (!flush()) return {};
        } else {
            item += c;
        }
    }
    return out;
}

class DisparityEvaluator : public binocle::sdk::Evaluator {
public:
    static std::vector<binocle_param_desc> parameters() {
        return {
            Param::yaml("thresholds_px", "[0.5, 1, 2, 4]")
                .help("bad-pixel thresholds in px (Middlebury's bad-0.5/1/2/4 by default); each gives bad_<t>px_*_percent"),
            Param::boolean("require_ground_truth", true)
                .help("fail when a frame carries no gt_disparity plane (false: report nothing for it)"),
        };
    }

    DisparityEvaluator(const binocle::sdk::CheckedParams &p, binocle::sdk::Host &host)
        : host_(host), thresholds_(parseThresholds(p.string("thresholds_px"))), require_(p.boolean("require_ground_truth")) {
        if (thresholds_.empty() || thresholds_.size() > 16)
            p.refuse("thresholds_px", p.string("thresholds_px"), "a list of 1 to 16 numbers >= 0 in px, e.g. [0.5, 1, 2, 4]");
        total_.all.bad.assign(thresholds_.size(), 0);
        total_.nonocc.bad.assign(thresholds_.size(), 0);
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
        const binocle_image *filledPlane =
            BINOCLE_EVAL_INPUT_HAS(in, disparity_extra_count)
                ? checkedPlane(findPlane(in.disparity_extras, in.disparity_extra_count, "disparity_filled"),
                               "the matcher's disparity_filled", d)
                : nullptr;
        const Frame f = score(*in.frame, *gt, d, filledPlane);
        report(f);
        total_.all.add(f.all);
        total_.nonocc.add(f.nonocc);
        total_.hasNonocc = total_.hasNonocc || f.hasNonocc;
        total_.hasFilled = total_.hasFilled || f.hasFilled;
        ++frames_;
    }

    void finish() override {
        if (frames_ == 0) return;
        host_.metric("frames", frames_);
        report(total_);
    }

private:
    const binocle_image *mask(const binocle_stereo_frame &frame, const char *name, const binocle_image &d) const {
        return checkedPlane(findExtra(frame, name), name, d);
    }

    static const binocle_image *checkedPlane(const binocle_image *m, const std::string &name, const binocle_image &d) {
        if (m && (m->format != BINOCLE_PIXEL_GRAY8 || m->width != d.width || m->height != d.height))
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "disparity evaluator: " + name + " is " +
                                                          std::to_string(m->width) + "x" + std::to_string(m->height) +
                                                          " (format " + std::to_string(m->format) +
                                                          "): expected GRAY8 of the disparity map's size");
        return m;
    }

    Frame score(const binocle_stereo_frame &frame, const binocle_image &gt, const binocle_image &d,
                const binocle_image *filledPlane) const {
        const binocle_image *valid = mask(frame, "gt_valid", d);
        const binocle_image *nonocc = mask(frame, "gt_nonocc", d);
        const std::vector<float> filled = backgroundFilled(d);
        Frame f;
        f.hasNonocc = nonocc != nullptr;
        f.hasFilled = filledPlane != nullptr;
        f.all.bad.assign(thresholds_.size(), 0);
        f.nonocc.bad.assign(thresholds_.size(), 0);
        for (int v = 0; v < d.height; ++v)
            for (int u = 0; u < d.width; ++u) {
                const float g = at<float>(gt, u, v);
                if (!(g > 0) || !std::isfinite(g)) continue;
                if (valid && at<uint8_t>(*valid, u, v) == 0) continue;
                // A disparity beyond the image's width cannot be one of this image: a file
                // read with the wrong scale is refused, not scored.
                if (g >= static_cast<float>(d.width))
                    throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                                "disparity evaluator: frame " + std::to_string(frame.sequence) + ": gt_disparity is " +
                                    std::to_string(g) + " px at (" + std::to_string(u) + ", " + std::to_string(v) +
                                    "), not less than the image width " + std::to_string(d.width) +
                                    ": not a disparity of this image (ground truth read with the wrong scale?)");
                const float x = at<float>(d, u, v);
                const float y = filled[static_cast<size_t>(v) * d.width + u];
                const double e1 = std::fabs(static_cast<double>(y) - g);
                const bool d1 = !std::isfinite(y) || (e1 > 3.0 && e1 > 0.05 * g);
                for (Tally *t : {&f.all, nonocc && at<uint8_t>(*nonocc, u, v) != 0 ? &f.nonocc : nullptr}) {
                    if (!t) continue;
                    t->n += 1;
                    t->d1 += d1 ? 1 : 0;
                    if (isHole(x)) {
                        t->invalid += 1;
                        for (double &b : t->bad) b += 1;
                        continue;
                    }
                    if (filledPlane && at<uint8_t>(*filledPlane, u, v) != 0) t->filled += 1;
                    const double e = std::fabs(static_cast<double>(x) - g);
                    t->sum_abs += e;
                    t->sum_sq += e * e;
                    for (size_t i = 0; i < thresholds_.size(); ++i)
                        if (e > thresholds_[i]) t->bad[i] += 1;
                }
            }
        return f;
    }

    void reportRegion(const Tally &t, const char *region, const char *kitti) {
        auto percent = [&](double count) { return t.n > 0 ? 100.0 * count / t.n : NAN; };
        const double matched = t.n - t.invalid;
        for (size_t i = 0; i < thresholds_.size(); ++i) {
            char name[64];
            std::snprintf(name, sizeof name, "bad_%gpx_%s_percent", thresholds_[i], region);
            host_.metric(name, percent(t.bad[i]), "%");
        }
        host_.metric(std::string("avgerr_") + region + "_px", matched > 0 ? t.sum_abs / matched : NAN, "px");
        host_.metric(std::string("rms_") + region + "_px", matched > 0 ? std::sqrt(t.sum_sq / matched) : NAN, "px");
        host_.metric(std::string("invalid_") + region + "_percent", percent(t.invalid), "%");
        host_.metric(std::string("d1_") + kitti + "_percent", percent(t.d1), "%");
    }

    void report(const Frame &f) {
        if (f.hasNonocc) reportRegion(f.nonocc, "nonocc", "noc");
        reportRegion(f.all, "all", "all");
        // The share of the scored pixels whose disparity the matcher filled in rather than
        // matched (its disparity_filled plane: sgm's fill: dense), so that a dense matcher's
        // figures can be told from a sparse one's.
        if (f.hasFilled) {
            if (f.hasNonocc) host_.metric("filled_nonocc_percent", f.nonocc.n > 0 ? 100.0 * f.nonocc.filled / f.nonocc.n : NAN, "%");
            host_.metric("filled_all_percent", f.all.n > 0 ? 100.0 * f.all.filled / f.all.n : NAN, "%");
        }
        host_.metric("density_percent", f.all.n > 0 ? 100.0 * (f.all.n - f.all.invalid) / f.all.n : NAN, "%");
        host_.metric("ground_truth_pixels", f.all.n);
        if (f.hasNonocc) host_.metric("nonocc_pixels", f.nonocc.n);
    }

    binocle::sdk::Host &host_;
    std::vector<double> thresholds_;
    bool require_;
    Frame total_;
    int frames_ = 0;
};

} // namespace

BINOCLE_EXPORT_EVALUATOR(DisparityEvaluator, "disparity", "2.0.0",
                         "Middlebury bad-pixel rates, avgerr, rms and invalid share over non-occluded and all pixels, "
                         "KITTI D1, density, against the source's ground-truth disparity")
