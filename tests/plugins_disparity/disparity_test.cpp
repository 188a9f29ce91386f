// SPDX-License-Identifier: MIT
// The `disparity` evaluator's figures against figures computed by hand on an 8 x 2 image:
// Middlebury's bad-0.5/1/2/4, avgerr, rms, invalid % over non-occluded and all pixels
// (holes counted as errors in the bad rates), KITTI's D1 on the background-filled map.
#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

using binocle::Evaluator;
using binocle::HostSink;
using binocle::PluginHost;
using binocle::PluginRecord;

namespace {

const PluginRecord &disparityRecord() {
    static const std::unique_ptr<PluginHost> host = [] {
        auto h = std::make_unique<PluginHost>(std::vector<std::string>{BINOCLE_BUILD_PLUGIN_DIR});
        h->scan();
        return h;
    }();
    return host->require("disparity", BINOCLE_KIND_EVALUATOR);
}

struct EvalRun {
    std::map<std::string, double> metrics;
    std::unique_ptr<Evaluator> evaluator;
    explicit EvalRun(const std::string &yaml = "{}") {
        HostSink sink;
        sink.metric = [this](const std::string &n, double v, const std::string &) { metrics[n] = v; };
        sink.log = [](int32_t, const std::string &) {};
        evaluator = std::make_unique<Evaluator>(disparityRecord(), binocle::paramsFromYaml(disparityRecord(), yaml), sink);
    }
};

constexpr float kHole = 0.0f;
// Ground truth (0: unknown), the matcher's disparity (0, -1, NaN: holes), the non-occluded mask.
const float kGt[2][8] = {{2, 2, 2, 2, 3, 3, 3, 3}, {0, 4, 4, 4, 4, 5, 5, 5}};
const float kD[2][8] = {{2.2f, 3.0f, kHole, 2.0f, 6.5f, 3.4f, 3.0f, NAN}, {1.0f, 4.0f, 4.6f, 9.0f, 4.0f, 9.5f, -1.0f, 5.0f}};
const uint8_t kNonocc[2][8] = {{255, 255, 255, 255, 0, 255, 255, 255}, {255, 255, 255, 0, 255, 255, 255, 255}};

struct Frame {
    std::vector<float> gt, d;
    std::vector<uint8_t> nonocc;
    binocle_named_image extras[2]{};
    binocle_stereo_frame f{};
    binocle_image disparity{};
    binocle_eval_input in{};

    explicit Frame(bool withNonocc, float gtScale = 1.0f) {
        for (int v = 0; v < 2; ++v)
            for (int u = 0; u < 8; ++u) {
                gt.push_back(kGt[v][u] * gtScale);
                d.push_back(kD[v][u]);
                nonocc.push_back(kNonocc[v][u]);
            }
        extras[0] = {"gt_disparity", image(gt.data(), BINOCLE_PIXEL_FLOAT32, 32)};
        extras[1] = {"gt_nonocc", image(nonocc.data(), BINOCLE_PIXEL_GRAY8, 8)};
        f.struct_size = sizeof f;
        f.extras = extras;
        f.extra_count = withNonocc ? 2 : 1;
        disparity = image(d.data(), BINOCLE_PIXEL_FLOAT32, 32);
        in.struct_size = sizeof in;
        in.frame = &f;
        in.disparity = &disparity;
    }
    static binocle_image image(void *data, int32_t format, int32_t stride) {
        binocle_image im{};
        im.width = 8;
        im.height = 2;
        im.format = format;
        im.data = data;
        im.stride_bytes = stride;
        return im;
    }
};

// Figures by hand. Known: 15 pixels (all but row 1, column 0); holes: 3 (row 0 columns 2
// and 7, row 1 column 6); non-occluded: 13 (row 0 column 4 and row 1 column 3 are not).
// Errors of the 12 matched pixels: 0.2 1.0 0 3.5 0.4 0 | 0 0.6 5.0 0 4.5 0; of the 10
// non-occluded ones: the same less 3.5 and 5.0.
TEST(DisparityEvaluator, MiddleburyAndKittiFiguresAsComputedByHand) {
    EvalRun run;
    Frame frame(true);
    run.evaluator->evaluate(frame.in);
    auto &m = run.metrics;
    EXPECT_DOUBLE_EQ(m.at("ground_truth_pixels"), 15);
    EXPECT_DOUBLE_EQ(m.at("nonocc_pixels"), 13);
    EXPECT_NEAR(m.at("density_percent"), 100.0 * 12 / 15, 1e-9);
    // all: bad = matched errors above t, plus the 3 holes, over 15.
    EXPECT_NEAR(m.at("bad_0.5px_all_percent"), 100.0 * (5 + 3) / 15, 1e-9); // 1.0 3.5 0.6 5.0 4.5
    EXPECT_NEAR(m.at("bad_1px_all_percent"), 100.0 * (3 + 3) / 15, 1e-9);   // 1.0 is not above 1
    EXPECT_NEAR(m.at("bad_2px_all_percent"), 100.0 * (3 + 3) / 15, 1e-9);
    EXPECT_NEAR(m.at("bad_4px_all_percent"), 100.0 * (2 + 3) / 15, 1e-9);
    EXPECT_NEAR(m.at("avgerr_all_px"), 15.2 / 12, 1e-6);
    EXPECT_NEAR(m.at("rms_all_px"), std::sqrt(59.06 / 12), 1e-6);
    EXPECT_NEAR(m.at("invalid_all_percent"), 100.0 * 3 / 15, 1e-9);
    // nonocc.
    EXPECT_NEAR(m.at("bad_0.5px_nonocc_percent"), 100.0 * (3 + 3) / 13, 1e-9); // 1.0 0.6 4.5
    EXPECT_NEAR(m.at("bad_1px_nonocc_percent"), 100.0 * (1 + 3) / 13, 1e-9);
    EXPECT_NEAR(m.at("bad_4px_nonocc_percent"), 100.0 * (1 + 3) / 13, 1e-9);
    EXPECT_NEAR(m.at("avgerr_nonocc_px"), 6.7 / 10, 1e-6);
    EXPECT_NEAR(m.at("rms_nonocc_px"), std::sqrt(21.81 / 10), 1e-6);
    EXPECT_NEAR(m.at("invalid_nonocc_percent"), 100.0 * 3 / 13, 1e-9);
    // KITTI D1 on the map filled as the devkit fills it: row 0 column 2 takes min(3.0, 2.0)
    // = 2 (right), column 7 the 3.0 on its left (right); row 1 column 6 min(9.5, 5) = 5
    // (right). Errors > 3 px and > 5 %: 3.5 (occluded), 5.0 (occluded), 4.5.
    EXPECT_NEAR(m.at("d1_all_percent"), 100.0 * 3 / 15, 1e-9);
    EXPECT_NEAR(m.at("d1_noc_percent"), 100.0 * 1 / 13, 1e-9);

    // The run's totals pool the pixels of every frame: the same frame twice, the same rates.
    run.evaluator->evaluate(frame.in);
    run.evaluator->finish();
    EXPECT_DOUBLE_EQ(m.at("frames"), 2);
    EXPECT_DOUBLE_EQ(m.at("ground_truth_pixels"), 30);
    EXPECT_NEAR(m.at("bad_1px_nonocc_percent"), 100.0 * 4 / 13, 1e-9);
}

TEST(DisparityEvaluator, WithoutGtNonoccTheNonoccFiguresAreAbsent) {
    EvalRun run("{thresholds_px: [3]}");
    Frame frame(false);
    run.evaluator->evaluate(frame.in);
    EXPECT_EQ(run.metrics.count("bad_3px_nonocc_percent"), 0u);
    EXPECT_EQ(run.metrics.count("avgerr_nonocc_px"), 0u);
    EXPECT_EQ(run.metrics.count("d1_noc_percent"), 0u);
    EXPECT_EQ(run.metrics.count("nonocc_pixels"), 0u);
    EXPECT_NEAR(run.metrics.at("bad_3px_all_percent"), 100.0 * (3 + 3) / 15, 1e-9); // 3.5 5.0 4.5 and the holes
}

// A matcher's disparity_filled plane (sgm's fill: dense): the share of the scored pixels
// whose value was filled in, not matched. Marked: row 0 columns 0 and 4 (matched, known;
// column 4 occluded), row 1 column 0 (no ground truth: not scored), row 1 column 6 (a hole:
// not a filled value).
TEST(DisparityEvaluator, TheMatchersFilledPixelsAreCounted) {
    EvalRun run;
    Frame frame(true);
    std::vector<uint8_t> filled(16, 0);
    filled[0] = filled[4] = filled[8] = filled[14] = 255;
    binocle_named_image plane{"disparity_filled", Frame::image(filled.data(), BINOCLE_PIXEL_GRAY8, 8)};
    frame.in.disparity_extras = &plane;
    frame.in.disparity_extra_count = 1;
    run.evaluator->evaluate(frame.in);
    EXPECT_NEAR(run.metrics.at("filled_all_percent"), 100.0 * 2 / 15, 1e-9);
    EXPECT_NEAR(run.metrics.at("filled_nonocc_percent"), 100.0 * 1 / 13, 1e-9);
    // Without the plane (a sparse matcher, or a host of API 1) the figures are absent.
    EvalRun sparse;
    Frame plain(true);
    sparse.evaluator->evaluate(plain.in);
    EXPECT_EQ(sparse.metrics.count("filled_all_percent"), 0u);
    // A plane of another size or format is refused, naming it.
    std::vector<float> wrong(16, 0);
    plane.image = Frame::image(wrong.data(), BINOCLE_PIXEL_FLOAT32, 32);
    try {
        run.evaluator->evaluate(frame.in);
        FAIL() << "a FLOAT32 disparity_filled plane was accepted";
    } catch (const std::exception &e) {
        EXPECT_NE(std::string(e.what()).find("disparity_filled"), std::string::npos) << e.what();
    }
}

TEST(DisparityEvaluator, AGroundTruthBeyondTheWidthOrBadThresholdsAreRefused) {
    EvalRun run;
    Frame frame(true, 255.0f); // what a PFM read by its -1/255 scale's magnitude gives
    try {
        run.evaluator->evaluate(frame.in);
        FAIL() << "scored a ground truth of 510 px on an 8-pixel-wide image";
    } catch (const std::exception &e) {
        EXPECT_NE(std::string(e.what()).find("image width 8"), std::string::npos) << e.what();
    }
    for (const char *bad : {"[1, x]", "[-1]", "[]", "[0x1]", "[inf]", "[1, nan]"}) {
        try {
            EvalRun(std::string("{thresholds_px: ") + bad + "}");
            FAIL() << "accepted thresholds_px " << bad;
        } catch (const std::exception &e) { // the one form of a refused setting (binocle/settings.hpp)
            EXPECT_NE(std::string(e.what()).find("disparity: thresholds_px = "), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(": expected a list of 1 to 16 numbers >= 0 in px"), std::string::npos) << e.what();
        }
    }
}

} // namespace
