// SPDX-License-Identifier: MIT
// nonocc_probe: a test Evaluator that reports what it finds of the frame extra
// `gt_nonocc` in its input (the plane the sim source delivers beside gt_disparity), so
// that a test can see the mask arrive through a run: nonocc_pixels (non-zero),
// occluded_pixels (ground truth known, mask 0), nonocc_unknown_pixels (non-zero without
// ground truth), and the share of matched pixels off by more than 1 px in each set.
// Fails a frame whose gt_nonocc is missing or not GRAY8 of the disparity's size.
#include <binocle/plugin.hpp>

#include <opencv2/core.hpp>

#include <cmath>
#include <map>
#include <string>
#include <tuple>

namespace {

using binocle::sdk::Error;

cv::Mat viewOf(const binocle_image &im, int type) {
    return cv::Mat(im.height, im.width, type, const_cast<void *>(im.data), static_cast<size_t>(im.stride_bytes));
}

class NonoccProbe : public binocle::sdk::Evaluator {
public:
    static std::vector<binocle_param_desc> parameters() { return {}; }
    NonoccProbe(const binocle::sdk::CheckedParams &, binocle::sdk::Host &host) : host_(host) {}

    void evaluate(const binocle_eval_input &in) override {
        std::map<std::string, const binocle_image *> extras;
        for (int32_t i = 0; i < in.frame->extra_count; ++i)
            if (in.frame->extras[i].name) extras[in.frame->extras[i].name] = &in.frame->extras[i].image;
        const binocle_image &d = *in.disparity;
        if (!extras.count("gt_nonocc") || !extras.count("gt_disparity"))
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "nonocc_probe: the frame carries no gt_nonocc or gt_disparity");
        const binocle_image &m = *extras["gt_nonocc"], &t = *extras["gt_disparity"];
        for (const auto &[name, im, format] : {std::tuple{"gt_nonocc", &m, BINOCLE_PIXEL_GRAY8}, {"gt_disparity", &t, BINOCLE_PIXEL_FLOAT32}})
            if (im->format != format || im->width != d.width || im->height != d.height)
                throw Error(BINOCLE_ERR_INVALID_ARGUMENT, std::string("nonocc_probe: ") + name + " is " + binocle::sdk::sizeText(*im) +
                                                              " " + binocle::sdk::pixelFormatName(im->format) + ": expected " +
                                                              binocle::sdk::pixelFormatName(format) + " of the disparity's size");
        const cv::Mat mask = viewOf(m, CV_8U), truth = viewOf(t, CV_32F), disparity = viewOf(d, CV_32F);
        double count[2] = {0, 0}, matched[2] = {0, 0}, bad[2] = {0, 0}; // [0] non-occluded, [1] occluded
        double unknown = 0;
        for (int v = 0; v < d.height; ++v)
            for (int u = 0; u < d.width; ++u) {
                const float g = truth.at<float>(v, u), x = disparity.at<float>(v, u);
                const int set = mask.at<uint8_t>(v, u) != 0 ? 0 : 1;
                if (!(g > 0) || !std::isfinite(g)) {
                    unknown += set == 0;
                    continue;
                }
                count[set] += 1;
                if (!(x > 0) || !std::isfinite(x)) continue;
                matched[set] += 1;
                if (std::fabs(x - g) > 1) bad[set] += 1;
            }
        host_.metric("nonocc_pixels", count[0]);
        host_.metric("occluded_pixels", count[1]);
        host_.metric("nonocc_unknown_pixels", unknown);
        host_.metric("error_over_1px_nonocc_percent", matched[0] > 0 ? 100 * bad[0] / matched[0] : NAN, "%");
        host_.metric("error_over_1px_occluded_percent", matched[1] > 0 ? 100 * bad[1] / matched[1] : NAN, "%");
    }

private:
    binocle::sdk::Host &host_;
};

} // namespace

BINOCLE_EXPORT_EVALUATOR(NonoccProbe, "nonocc_probe", "1.0.0", "test probe: the gt_nonocc extra an evaluator receives")
