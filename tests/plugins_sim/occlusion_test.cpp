// SPDX-License-Identifier: MIT
// The sim's occlusion mask `gt_nonocc`: against a scene whose occluded pixels are known
// analytically (a board before a wall), on a misaligned head in the rectified grid, on
// the E1 panel, and through a run to an evaluator's input.
#include "sim_test_util.hpp"

#include "common/test_util.hpp"
#include "config/rig_config.hpp"
#include "pipeline/pipeline.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <iostream>
#include <string>

namespace binocle::test {
namespace {

const std::string kSceneFile = std::string(BINOCLE_SOURCE_DIR) + "/tests/plugins_sim/occlusion_band.yaml";

// occlusion_band.yaml, written out: the board's front face and extent, the wall's face.
constexpr double kBoardY = 4000, kBoardX0 = -600, kBoardX1 = 900, kBoardZ0 = 1000, kBoardZ1 = 2200;
constexpr double kWallY = 10000;

sim::RenderSettings exact() {
    sim::RenderSettings r;
    r.noise_sigma = 0;
    r.antialias = 1;
    return r;
}

// What the level, ideal head (centres at X 0 and B, height hc) sees at pixel (u, v) of
// occlusion_band.yaml, from the geometry alone: 255 when the surface the left ray meets
// is seen by the right imager, 0 when the board hides it or it falls outside the right
// image. Rows are shared by both imagers, so only X decides.
uint8_t expectedNonocc(int u, int v, const sim::RigSettings &s) {
    const double f = s.focalLengthPx(), cx = (s.image_width - 1) / 2.0, cy = (s.image_height - 1) / 2.0;
    const double x = (u - cx) / f, y = (v - cy) / f, B = s.baseline_mm;
    auto onBoard = [&](double X, double Z) { return X >= kBoardX0 && X <= kBoardX1 && Z >= kBoardZ0 && Z <= kBoardZ1; };
    const double boardZ = s.camera_height_mm - y * kBoardY; // height where this row meets the board's plane
    if (onBoard(x * kBoardY, boardZ)) return 255;           // the board: nothing before it, inside both images
    const double wallX = x * kWallY;
    const double rightU = u - f * B / kWallY;               // where the right image has that point
    if (rightU < -0.5) return 0;                            // left of the right image
    const double crossX = B + (wallX - B) * kBoardY / kWallY; // the right ray through the board's plane
    return onBoard(crossX, boardZ) ? 0 : 255;
}

// Test: the mask is the analytic one on every pixel, and on each row through the board it
// has a band of d_board - d_wall pixels (within one) just left of the board's left edge:
// the left pixel u sees the wall, which the right imager has at u - d_wall, where the
// board covers u' >= u_edge - d_board; so u_edge - (d_board - d_wall) <= u < u_edge.
TEST(SimOcclusion, BandLeftOfTheBoardIsTheDisparityStepWide) {
    const sim::RigSettings s;
    const sim::Scene scene = sim::Scene::load(kSceneFile);
    const sim::StereoRig rig(s);
    const sim::RenderedFrame f = sim::Renderer(rig, exact()).render(scene, {}, 0);
    ASSERT_EQ(f.gt_nonocc.type(), CV_8UC1);
    ASSERT_EQ(f.gt_nonocc.size(), f.left.size());
    int wrong = 0;
    for (int v = 0; v < s.image_height; ++v)
        for (int u = 0; u < s.image_width; ++u)
            if (f.gt_nonocc.at<uint8_t>(v, u) != expectedNonocc(u, v, s) && ++wrong <= 10)
                ADD_FAILURE() << "pixel " << u << "," << v << ": mask " << int(f.gt_nonocc.at<uint8_t>(v, u))
                              << ", expected " << int(expectedNonocc(u, v, s));
    EXPECT_EQ(wrong, 0);

    const double fpx = s.focalLengthPx(), step = fpx * s.baseline_mm * (1 / kBoardY - 1 / kWallY); // 8.65 px
    const uint16_t board = scene.objects.at(static_cast<size_t>(scene.findObject("board"))).id;
    int rows = 0;
    for (int v = 0; v < s.image_height; ++v) {
        int edge = 0;
        while (edge < s.image_width && f.gt_object_id.at<uint16_t>(v, edge) != board) ++edge;
        if (edge == s.image_width) continue;
        ++rows;
        int band = 0;
        while (band < edge && f.gt_nonocc.at<uint8_t>(v, edge - 1 - band) == 0) ++band;
        EXPECT_LE(std::abs(band - step), 1.0) << "row " << v << ": band of " << band << " px, step " << step;
        // The board's own pixels are seen by both imagers.
        EXPECT_EQ(f.gt_nonocc.at<uint8_t>(v, edge), 255) << "row " << v;
    }
    EXPECT_GT(rows, 100);
    std::cout << "[ figures  ] occluded band " << step << " px wide expected on " << rows << " rows\n";
}

// The rectified right imager is the partner of the ground truth's grid: the point seen at
// rectified left pixel (u, v) lands on (u - gt_disparity, v) there, on a misaligned,
// distorted, inclined head too.
TEST(SimOcclusion, RectifiedRightImagerMatchesTheGroundTruthDisparity) {
    const sim::RigSettings s = imperfectRig();
    const sim::Scene scene = sim::Scene::load(kSceneFile);
    const sim::StereoRig rig(s);
    const sim::RenderedFrame f = sim::Renderer(rig, exact()).render(scene, {}, 0);
    const sim::Camera left = rig.rectifiedLeft({}), right = rig.rectifiedRight({});
    double worst = 0;
    for (int v = 0; v < s.image_height; v += 7)
        for (int u = 0; u < s.image_width; u += 7) {
            const double z = f.gt_depth.at<float>(v, u);
            ASSERT_GT(z, 0) << "the wall fills the view";
            const sim::Vec3 p = left.center + left.direction(u, v) * z; // direction(): unit depth
            double ru = 0, rv = 0;
            ASSERT_TRUE(right.project(p, ru, rv));
            worst = std::max({worst, std::abs(ru - (u - f.gt_disparity.at<float>(v, u))), std::abs(rv - v)});
        }
    EXPECT_LT(worst, 2e-3); // gt_disparity and gt_depth are FLOAT32
}

// On the misaligned head the band left of the board, in the rectified grid, is still the
// disparity step wide (read from gt_disparity on either side) within one pixel.
TEST(SimOcclusion, ImperfectRigBandIsTheDisparityStepWide) {
    const sim::RigSettings s = imperfectRig();
    const sim::Scene scene = sim::Scene::load(kSceneFile);
    const sim::StereoRig rig(s);
    const sim::RenderedFrame f = sim::Renderer(rig, exact()).render(scene, {}, 0);
    const uint16_t board = scene.objects.at(static_cast<size_t>(scene.findObject("board"))).id;
    auto firstBoardColumn = [&](int v) {
        int u = 0;
        while (u < s.image_width && f.gt_object_id.at<uint16_t>(v, u) != board) ++u;
        return u;
    };
    int rows = 0;
    for (int v = 3; v < s.image_height - 3; ++v) {
        const int edge = firstBoardColumn(v);
        // Rows well inside the board's height: its top and bottom edges make no band.
        if (edge == s.image_width || firstBoardColumn(v - 3) == s.image_width || firstBoardColumn(v + 3) == s.image_width)
            continue;
        ++rows;
        int band = 0;
        while (band < edge && f.gt_nonocc.at<uint8_t>(v, edge - 1 - band) == 0) ++band;
        ASSERT_LT(band, edge) << "row " << v;
        const double step = f.gt_disparity.at<float>(v, edge) - f.gt_disparity.at<float>(v, edge - 1 - band);
        EXPECT_LE(std::abs(band - step), 1.0) << "row " << v << ": band of " << band << " px, step " << step;
    }
    EXPECT_GT(rows, 50);
}

// On the E1 panel the mask holds only known pixels, hides the ground just left of each
// cube column and the columns the right image does not reach, and keeps the rest.
TEST(SimOcclusion, E1PanelMaskIsInsideTheKnownTruth) {
    const sim::RigSettings s;
    const sim::StereoRig rig(s);
    const sim::RenderedFrame f = sim::Renderer(rig, sim::RenderSettings{}).render(sim::Scene::builtIn(), {}, 0);
    const cv::Mat outside = f.gt_nonocc & ~f.gt_valid;
    EXPECT_EQ(cv::countNonZero(outside), 0) << "non-occluded but unknown";
    const int known = cv::countNonZero(f.gt_valid), nonocc = cv::countNonZero(f.gt_nonocc);
    EXPECT_LT(nonocc, known);
    EXPECT_GT(nonocc, known * 9 / 10);
    // Pixels whose point the right image has left of its first column are never seen.
    int beyond = 0;
    for (int v = 0; v < s.image_height; ++v)
        for (int u = 0; u < s.image_width; ++u)
            if (u - f.gt_disparity.at<float>(v, u) < -0.5 && f.gt_valid.at<uint8_t>(v, u)) {
                ++beyond;
                EXPECT_EQ(f.gt_nonocc.at<uint8_t>(v, u), 0) << "pixel " << u << "," << v;
            }
    EXPECT_GT(beyond, 100);
    std::cout << "[ figures  ] E1 at 6 m: " << known - nonocc << " of " << known << " known pixels occluded\n";
}

// Test: through a run (sim source, sgm matcher, the `disparity` evaluator and a probe
// evaluator), the mask reaches an evaluator's input as the frame extra gt_nonocc, GRAY8
// of the disparity's size, with the pixels the source rendered; the known pixels the
// disparity evaluator counts split into non-occluded and occluded ones.
TEST(SimOcclusion, MaskReachesAnEvaluatorThroughARun) {
    const PluginHost host(std::vector<std::string>{BINOCLE_BUILD_PLUGIN_DIR, BINOCLE_SIM_PROBE_DIR});
    const std::string rigText = "name: occlusion\n"
                                "source: {plugin: sim, scene: occlusion_band.yaml, noise_sigma: 1}\n"
                                "matcher: {plugin: sgm, num_disparities: 32}\n"
                                "evaluators: [{plugin: disparity}, {plugin: nonocc_probe}]\n"
                                "outputs: {disparity_png: false, disparity_color: false, cloud_ply: false}\n";
    const RigConfig rig = loadRigText(rigText, std::string(BINOCLE_SOURCE_DIR) + "/tests/plugins_sim/occlusion_rig.yaml", {}, host);
    TempDir dir;
    Pipeline pipeline(rig, host);
    RunOptions o;
    o.out_dir = dir.str("out");
    o.progress = false;
    int frames = 0;
    double delivered = -1;
    nlohmann::ordered_json metrics;
    const auto summary = pipeline.run(o, [&](const FrameResult &r) {
        ++frames;
        const cv::Mat mask = r.frame->extra("gt_nonocc");
        ASSERT_EQ(mask.type(), CV_8UC1);
        delivered = cv::countNonZero(mask);
        metrics = r.metrics;
    });
    ASSERT_EQ(summary["status"], "ok") << summary.dump(2);
    ASSERT_EQ(frames, 1);
    const auto &probe = metrics.at("nonocc_probe"), &disparity = metrics.at("disparity");
    EXPECT_EQ(probe.at("nonocc_pixels").get<double>(), delivered);
    EXPECT_EQ(probe.at("nonocc_unknown_pixels").get<double>(), 0);
    EXPECT_GT(probe.at("occluded_pixels").get<double>(), 0);
    EXPECT_EQ(probe.at("nonocc_pixels").get<double>() + probe.at("occluded_pixels").get<double>(),
              disparity.at("ground_truth_pixels").get<double>());
    // The matcher's errors on seen pixels are few (a textured wall and board); on the
    // occluded ones, which no matcher can match, they are most of what it gives.
    EXPECT_LT(probe.at("error_over_1px_nonocc_percent").get<double>(), 5.0) << probe.dump();
    EXPECT_GT(probe.at("error_over_1px_occluded_percent").get<double>(), 25.0) << probe.dump();
    std::cout << "[ figures  ] sgm on occlusion_band: " << probe.dump() << "\n";
}

} // namespace
} // namespace binocle::test
