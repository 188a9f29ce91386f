// SPDX-License-Identifier: MIT
// paper evaluator through the plugin host: Eq. 2-7 on synthetic ground-frame clouds,
// truth from settings or frame metadata, rejected configurations, views, E2 indicators.
#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"
#include "synthetic_cloud.hpp"
#include "../common/test_util.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstddef>
#include <map>
#include <memory>
#include <string>

namespace binocle::test {
namespace {

const PluginRecord &paperRecord() {
    static const std::unique_ptr<PluginHost> host = [] {
        auto h = std::make_unique<PluginHost>(std::vector<std::string>{BINOCLE_BUILD_PLUGIN_DIR});
        h->scan();
        return h;
    }();
    return host->require("paper", BINOCLE_KIND_EVALUATOR);
}

// An evaluator with a sink that keeps the last value of every figure.
struct PaperRun {
    std::map<std::string, double> metrics;
    std::map<std::string, std::string> units, texts;
    std::vector<std::string> warnings;
    std::unique_ptr<Evaluator> evaluator;

    explicit PaperRun(const std::string &yaml) {
        HostSink sink;
        sink.metric = [this](const std::string &n, double v, const std::string &u) {
            metrics[n] = v;
            units[n] = u;
        };
        sink.text = [this](const std::string &n, const std::string &t) { texts[n] = t; };
        sink.log = [this](int32_t level, const std::string &m) {
            if (level >= BINOCLE_LOG_WARNING) warnings.push_back(m);
        };
        const PluginRecord &record = paperRecord();
        evaluator = std::make_unique<Evaluator>(record, paramsFromYaml(record, yaml), sink);
    }
    double operator[](const std::string &name) const {
        auto it = metrics.find(name);
        return it == metrics.end() ? -12345.0 : it->second;
    }
};

// One frame's input: a ground-frame cloud, its metadata, the rig, and what the host
// learnt from the matcher and the transforms.
struct Input {
    std::vector<float> xyz;
    std::string metadata, rig = "{}", calibration, output_dir;
    uint64_t sequence = 7;
    int32_t frame = BINOCLE_FRAME_GROUND;
    int32_t min_disparity = 0, num_disparities = 0; // the matcher's disparity_range
    bool ground_pose = false;                       // the ground frame's transform declared:
    double camera_height_mm = 0, inclination_deg = 0;
    uint32_t struct_size = sizeof(binocle_eval_input); // an older host passes less
    std::vector<binocle_named_image> extras;            // e.g. gt_disparity

    binocle_cloud cloud{};
    binocle_stereo_frame f{};
    binocle_eval_input in{};

    const binocle_eval_input &get() {
        cloud.count = static_cast<int64_t>(xyz.size() / 3);
        cloud.xyz = xyz.data();
        cloud.frame = frame;
        f.struct_size = sizeof f;
        f.sequence = sequence;
        f.metadata = metadata.empty() ? nullptr : metadata.c_str();
        f.extras = extras.empty() ? nullptr : extras.data();
        f.extra_count = static_cast<int32_t>(extras.size());
        in.struct_size = struct_size;
        in.frame = &f;
        in.min_disparity = min_disparity;
        in.num_disparities = num_disparities;
        in.ground_pose_known = ground_pose ? 1 : 0;
        in.camera_height_mm = camera_height_mm;
        in.inclination_deg = inclination_deg;
        in.cloud = &cloud;
        in.rig_yaml = rig.c_str();
        in.calibration_yaml = calibration.empty() ? nullptr : calibration.c_str();
        in.output_dir = output_dir.empty() ? nullptr : output_dir.c_str();
        return in;
    }
};

std::string errorOf(const std::function<void()> &f) {
    try {
        f();
    } catch (const std::exception &e) {
        return e.what();
    }
    return "";
}

const char *kTapeMeasured = "{panel_true_width_mm: 2500, panel_true_range_mm: 6000, panel_true_height_mm: 2000}";
const char *kSimMetadata = R"(frame: 7
scene: e1_panel
rig: {baseline_mm: 100, focal_length_mm: 2.8, pixel_pitch_um: 20.8, focal_length_px: 134.615384615,
      camera_height_mm: 1500, inclination_deg: 0, image_width: 320, image_height: 240}
main_object: panel
panel: {name: panel, width_mm: 2500, range_mm: 6000, height_mm: 2000, center_mm: [0, 6250, 1000]}
objects:
  - {name: panel, type: cube_matrix, id: 1, center_mm: [0, 6250, 1000], size_mm: [2500, 500, 2000], range_mm: 6000}
)";

TEST(PaperPlugin, ScoresThePanelWithTapeMeasuredTruth) {
    PaperRun run(kTapeMeasured);
    Input input;
    input.xyz = panelScene();
    run.evaluator->evaluate(input.get());
    EXPECT_EQ(run["registered"], 1);
    EXPECT_LT(run["epsilon_x_percent"], 0.3);
    EXPECT_LT(run["epsilon_y_percent"], 0.1);
    EXPECT_LT(run["epsilon_z_percent"], 0.3);
    EXPECT_GT(run["eta_2d_percent"], 99.7);
    EXPECT_GT(run["eta_3d_percent"], 99.7);
    EXPECT_NEAR(run["measured_width_mm"], 2500, 8);
    EXPECT_NEAR(run["measured_range_mm"], 6000, 3);
    EXPECT_NEAR(run["measured_height_mm"], 2000, 8);
    EXPECT_GT(run["panel_points"], 19000); // 9 faces of 0.5 m x 0.5 m every 10 mm, above the ground band
    EXPECT_EQ(run["objects_found"], 3);
    EXPECT_EQ(run.units["epsilon_x_percent"], "%");
    EXPECT_EQ(run.units["measured_width_mm"], "mm");
    EXPECT_NE(run.texts["objects"].find("\"center_x_mm\""), std::string::npos);
    // No B, f, p anywhere: no form factor (and no failure).
    EXPECT_EQ(run.metrics.count("form_factor"), 0u);
}

TEST(PaperPlugin, StretchedCloudThroughTheHost) {
    PaperRun run(kTapeMeasured);
    Input input;
    input.xyz = panelScene();
    stretchX(input.xyz, 1.05);
    run.evaluator->evaluate(input.get());
    EXPECT_NEAR(run["epsilon_x_percent"], 5, 0.5);
    EXPECT_NEAR(run["eta_2d_percent"], 100 - (run["epsilon_x_percent"] + run["epsilon_z_percent"]) / 2, 1e-9);
}

TEST(PaperPlugin, TruthAndGeometryFromTheSimMetadata) {
    PaperRun run("{}");
    Input input;
    input.xyz = panelScene();
    input.metadata = kSimMetadata;
    input.num_disparities = 64; // what the host's matcher answered
    run.evaluator->evaluate(input.get());
    EXPECT_EQ(run["registered"], 1);
    EXPECT_EQ(run["true_width_mm"], 2500);
    EXPECT_EQ(run["true_range_mm"], 6000);
    EXPECT_EQ(run["true_height_mm"], 2000);
    EXPECT_LT(run["epsilon_x_percent"], 0.3);
    // Test 1 of E1: B 100 mm, f 2.8 mm, R 6 m -> FF 0.47 (Eq. 7).
    EXPECT_NEAR(run["form_factor"], 0.47, 0.005);
    EXPECT_NEAR(run["disparity_px"], 100 * 2.8 / (6000 * 0.0208), 1e-9);
    EXPECT_NEAR(run["depth_resolution_mm"], 6000.0 * 6000 * 0.0208 * 0.25 / 280, 1e-6);
    EXPECT_NEAR(run["min_range_mm"], 280 / (0.0208 * 63), 1e-6);
    EXPECT_NEAR(run["horizontal_fov_deg"], 2 * std::atan(6.656 / 5.6) * 180 / M_PI, 1e-9);
    EXPECT_EQ(run["panel_fits"], 1);
    EXPECT_EQ(run.units["disparity_px"], "px");
}

// The matcher's search and the ground frame's pose come from the host (binocle_eval_input),
// never from another plugin's keys in the rig: any matcher and any ground transform work.
TEST(PaperPlugin, MatcherSearchAndGroundPoseComeFromTheHostNotTheRigKeys) {
    Input input;
    input.xyz = panelScene();
    input.metadata = kSimMetadata;
    input.rig = "{matcher: {plugin: sgbm, num_disparities: 16, min_disparity: 4},"
                " transforms: [{plugin: ground, camera_height_mm: 900, inclination_deg: 7}]}";
    input.num_disparities = 64;
    PaperRun run("{}");
    run.evaluator->evaluate(input.get());
    EXPECT_NEAR(run["min_range_mm"], 280 / (0.0208 * 63), 1e-6); // 64 from 0, not 16 from 4

    // An evaluator built with these fields in a host that predates them: unknown search,
    // no pose (the E2 inclination is the default 0), nothing read past struct_size.
    Input old = input;
    old.struct_size = offsetof(binocle_eval_input, output_dir) + sizeof(const char *);
    old.ground_pose = true;
    old.inclination_deg = 5.5;
    PaperRun older("{}");
    older.evaluator->evaluate(old.get());
    EXPECT_TRUE(std::isnan(older["min_range_mm"])) << older["min_range_mm"];

    PaperRun e2("{experiment: e2, object: panel}");
    e2.evaluator->evaluate(old.get());
    EXPECT_EQ(e2["inclination_applied_deg"], 0);
    input.ground_pose = true;
    input.inclination_deg = 5.5;
    PaperRun e2new("{experiment: e2, object: panel}");
    e2new.evaluator->evaluate(input.get());
    EXPECT_EQ(e2new["inclination_applied_deg"], 5.5);
}

TEST(PaperPlugin, SettingsOverrideTheMetadata) {
    PaperRun run("{panel_true_width_mm: 2625, baseline_mm: 150, focal_length_mm: 12}");
    Input input;
    input.xyz = panelScene();
    input.metadata = kSimMetadata;
    run.evaluator->evaluate(input.get());
    EXPECT_EQ(run["true_width_mm"], 2625);
    EXPECT_NEAR(run["epsilon_x_percent"], 100.0 * 125 / 2625, 0.3);
    EXPECT_NEAR(run["form_factor"], 3.00, 0.005); // Test 8: 150 mm, 12 mm, 6 m
}

TEST(PaperPlugin, NoPanelIsARejectedConfiguration) {
    PaperRun run(kTapeMeasured);
    Input input;
    SyntheticScene scene;
    scene.panel = false;
    input.xyz = panelScene(scene);
    run.evaluator->evaluate(input.get());
    EXPECT_EQ(run["registered"], 0);
    EXPECT_TRUE(std::isnan(run["epsilon_x_percent"]));
    EXPECT_TRUE(std::isnan(run["epsilon_y_percent"]));
    EXPECT_TRUE(std::isnan(run["epsilon_z_percent"]));
    EXPECT_EQ(run["eta_2d_percent"], 0);
    EXPECT_EQ(run["eta_3d_percent"], 0);
    ASSERT_FALSE(run.warnings.empty());
    EXPECT_NE(run.warnings[0].find("not registered"), std::string::npos) << run.warnings[0];

    // An empty cloud is no crash either.
    Input empty;
    run.evaluator->evaluate(empty.get());
    EXPECT_EQ(run["registered"], 0);
}

TEST(PaperPlugin, RefusesACameraFrameCloud) {
    PaperRun run(kTapeMeasured);
    Input input;
    input.xyz = panelScene();
    input.frame = BINOCLE_FRAME_CAMERA;
    const std::string e = errorOf([&] { run.evaluator->evaluate(input.get()); });
    EXPECT_NE(e.find("paper evaluator needs the cloud in the ground frame: add the ground transform"), std::string::npos)
        << e;
}

TEST(PaperPlugin, SaysWhenNoTruthIsKnown) {
    PaperRun run("{panel_true_width_mm: 2500}");
    Input input;
    input.xyz = panelScene();
    const std::string e = errorOf([&] { run.evaluator->evaluate(input.get()); });
    EXPECT_NE(e.find("no true panel size"), std::string::npos) << e;
    EXPECT_NE(e.find("panel_true_range_mm"), std::string::npos) << e;
    EXPECT_EQ(e.find("panel_true_width_mm"), std::string::npos) << e; // given
}

TEST(PaperPlugin, RefusesBadSettings) {
    const PluginRecord &record = paperRecord();
    const std::string range = errorOf([&] { Evaluator(record, paramsFromYaml(record, "{grid_y_mm: [5000, 100]}"), {}); });
    EXPECT_NE(range.find("grid_y_mm"), std::string::npos) << range;
    const std::string pair = errorOf([&] { Evaluator(record, paramsFromYaml(record, "{object_center_mm: [0, 6000, 250]}"), {}); });
    EXPECT_NE(pair.find("object_size_mm"), std::string::npos) << pair;
    const std::string cell = errorOf([&] { paramsFromYaml(record, "{cell_size_mm: 0}"); });
    EXPECT_NE(cell.find("cell_size_mm"), std::string::npos) << cell;
}

TEST(PaperPlugin, WritesTheThreeDensityViews) {
    TempDir dir;
    PaperRun run(std::string(kTapeMeasured).insert(1, "write_views: true, "));
    Input input;
    input.xyz = panelScene();
    input.output_dir = dir.str();
    run.evaluator->evaluate(input.get());
    for (const char *view : {"top", "front", "side"}) {
        const std::string path = dir.str(std::string("paper_") + view + "_000007.png");
        const cv::Mat img = cv::imread(path);
        EXPECT_FALSE(img.empty()) << path;
        EXPECT_GT(img.cols, 300) << path;
    }
    // Without an output folder: a warning, nothing written, no failure.
    Input nowhere;
    nowhere.xyz = panelScene();
    run.evaluator->evaluate(nowhere.get());
    EXPECT_FALSE(run.warnings.empty());
}

// What the reading took is drawn: the outline of the panel's cells in the front and top
// views (view_overlays, which `binocle view` draws) and in the PNG views (the report's).
TEST(PaperPlugin, TheReadCellsAreDrawnOverTheViews) {
    TempDir dir;
    PaperRun run(std::string(kTapeMeasured).insert(1, "write_views: true, "));
    Input input;
    input.xyz = panelScene();
    input.output_dir = dir.str();
    run.evaluator->evaluate(input.get());
    const nlohmann::json overlays = nlohmann::json::parse(run.texts.at("view_overlays"));
    for (const char *view : {"front", "top"}) {
        const nlohmann::json *panel = nullptr;
        for (const auto &o : overlays[view])
            if (o.contains("cells_mm")) panel = &o;
        ASSERT_NE(panel, nullptr) << view << ": " << overlays.dump();
        EXPECT_EQ((*panel)["cell_mm"], 100);
        EXPECT_NE((*panel)["label"].get<std::string>().find("X' 2.50 m"), std::string::npos) << (*panel)["label"];
        for (const auto &c : (*panel)["cells_mm"]) {
            EXPECT_GE(c[0].get<double>(), -1300) << view;
            EXPECT_LT(c[0].get<double>(), 1300) << view;
        }
    }
    // The front view's picture has the outline's colour (BGR 40, 40, 220) where the panel is.
    const cv::Mat front = cv::imread(dir.str("paper_front_000007.png"));
    ASSERT_FALSE(front.empty());
    cv::Mat red;
    cv::inRange(front, cv::Scalar(30, 30, 200), cv::Scalar(60, 60, 240), red);
    EXPECT_GT(cv::countNonZero(red), 400);
}

// The oracle: a frame carrying gt_disparity (as the sim's does) is read a second time
// on the cloud that disparity gives through the calibration's Q and Eq. 1; a frame
// without it reports no oracle figure.
TEST(PaperPlugin, OracleReadsTheGroundTruthDisparity) {
    const double f = 400, cx = 159.5, cy = 119.5, B = 100, hc = 1500, Zc = 6000;
    cv::Mat gt(240, 320, CV_32F, cv::Scalar(-1));
    for (int v = 0; v < gt.rows; ++v)
        for (int u = 0; u < gt.cols; ++u) {
            const double X = (u - cx) * Zc / f, Z = hc - (v - cy) * Zc / f;
            const double col = (X + 1250) / 1000, row = Z / 750;
            const bool cube = X >= -1250 && X < 1250 && Z >= 0 && Z < 2000 && col - std::floor(col) < 0.5 &&
                              row - std::floor(row) < 2.0 / 3;
            if (cube) gt.at<float>(v, u) = static_cast<float>(f * B / Zc);
            else if (v > cy) gt.at<float>(v, u) = static_cast<float>(B * (v - cy) / hc); // the ground
        }
    const std::string calibration = "%YAML:1.0\n---\nQ: !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: d\n   data: [1, 0, 0, " +
                                    std::to_string(-cx) + ", 0, 1, 0, " + std::to_string(-cy) + ", 0, 0, 0, " +
                                    std::to_string(f) + ", 0, 0, " + std::to_string(1 / B) + ", 0]\n";
    PaperRun run(kTapeMeasured);
    Input input;
    input.xyz = panelScene();
    input.calibration = calibration;
    input.ground_pose = true;
    input.camera_height_mm = hc;
    input.extras.push_back({"gt_disparity", {gt.cols, gt.rows, static_cast<int32_t>(gt.step), BINOCLE_PIXEL_FLOAT32, gt.data}});
    run.evaluator->evaluate(input.get());
    EXPECT_EQ(run["registered_oracle"], 1);
    EXPECT_GT(run["eta_3d_oracle_percent"], 97);
    EXPECT_NEAR(run["measured_width_oracle_mm"], 2500, 60);
    EXPECT_NEAR(run["eta_3d_matcher_loss_percent"], run["eta_3d_oracle_percent"] - run["eta_3d_percent"], 1e-9);

    PaperRun without(kTapeMeasured);
    Input plain;
    plain.xyz = panelScene();
    plain.calibration = calibration;
    without.evaluator->evaluate(plain.get());
    EXPECT_EQ(without.metrics.count("eta_3d_oracle_percent"), 0u);
}

TEST(PaperPlugin, FinishReportsMeansOverTheRun) {
    PaperRun run(kTapeMeasured);
    Input good;
    good.xyz = panelScene();
    run.evaluator->evaluate(good.get());
    const double eta = run["eta_3d_percent"];
    Input none;
    SyntheticScene scene;
    scene.panel = false;
    none.xyz = panelScene(scene);
    run.evaluator->evaluate(none.get());
    run.evaluator->finish();
    EXPECT_EQ(run["frames"], 2);
    EXPECT_EQ(run["registered"], 0.5);
    EXPECT_NEAR(run["eta_3d_percent"], eta / 2, 1e-9);              // the rejected frame counts 0
    EXPECT_LT(run["epsilon_x_percent"], 0.3);                       // over the frames that have it
}

// E2: a camera pitched 6 deg down whose cloud was moved with Eq. 1 at 5.5 deg; a known
// marker box seen 40 mm left of where it is.
TEST(PaperPlugin, ExperimentTwoIndicators) {
    PaperRun run("{experiment: e2}");
    Input input;
    input.xyz = groundSeenWithInclination(1500, 6, 5.5, 8);
    CloudBuilder b(4);
    b.frontFace(-1250 - 40, -750 - 40, 50, 550, 6000, 10, 3); // the ground is 52 mm high there
    input.xyz.insert(input.xyz.end(), b.xyz.begin(), b.xyz.end());
    input.metadata = R"(rig: {baseline_mm: 150, focal_length_mm: 8, pixel_pitch_um: 20.8, inclination_deg: 6,
      camera_height_mm: 1500, image_width: 320, image_height: 240}
main_object: marker
objects:
  - {name: tree, type: tree, center_mm: [1200, 9000, 3000], size_mm: [3600, 3400, 6000]}
  - {name: marker, type: box, center_mm: [-1000, 6250, 250], size_mm: [500, 500, 500]}
)";
    input.ground_pose = true; // the host: the transform that made the ground frame applied
    input.camera_height_mm = 1500;
    input.inclination_deg = 5.5;
    run.evaluator->evaluate(input.get());
    EXPECT_EQ(run["registered"], 1);
    EXPECT_NEAR(run["object_offset_lateral_mm"], -40, 10);
    // The cells read as the marker are outlined in the front view too.
    const nlohmann::json overlays = nlohmann::json::parse(run.texts.at("view_overlays"));
    ASSERT_FALSE(overlays["front"].empty()) << overlays.dump();
    EXPECT_FALSE(overlays["front"][0]["cells_mm"].empty()) << overlays.dump();
    EXPECT_NEAR(run["object_offset_range_mm"], 0, 5);
    EXPECT_LT(run["epsilon_y_percent"], 0.1);
    EXPECT_EQ(run["inclination_applied_deg"], 5.5);
    EXPECT_NEAR(run["inclination_recovered_deg"], 6, 0.2);
    EXPECT_NEAR(run["angular_error_deg"], 0, 0.2);
    EXPECT_EQ(run["inclination_true_deg"], 6);
    EXPECT_NEAR(run["ground_pitch_deg"], 0.5, 0.2);
    EXPECT_NEAR(run["form_factor"], 2.0, 1e-9); // 10 * 150 * 8 / 6000
    EXPECT_EQ(run.metrics.count("eta_3d_percent"), 0u);

    PaperRun unknown("{experiment: e2, object: rock}");
    const std::string e = errorOf([&] { unknown.evaluator->evaluate(input.get()); });
    EXPECT_NE(e.find("no known object named 'rock'"), std::string::npos) << e;
}

} // namespace
} // namespace binocle::test
