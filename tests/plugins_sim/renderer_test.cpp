// SPDX-License-Identifier: MIT
// The sim source's renderer, called directly: projection against OpenCV's pinhole model,
// seeded noise, rectification with the published calibration, ground truth.
#include "sim_test_util.hpp"

#include "common/test_util.hpp"

#include "core/calibration.hpp"
#include "metadata.hpp"
#include "renderer.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <iostream>

namespace binocle::test {
namespace {

using sim::RenderSettings;
using sim::RigSettings;

RenderSettings exact(int antialias) {
    RenderSettings r;
    r.noise_sigma = 0;
    r.antialias = antialias;
    return r;
}

// Where OpenCV's model puts a ground-frame point in the left and right images, given the
// calibration the sim publishes (parsed by the framework, as a pipeline would).
void projectWithCalibration(const StereoCalibration &c, const RigSettings &s, const cv::Point3d &ground,
                            cv::Point2d &left, cv::Point2d &right) {
    const std::vector<cv::Point3d> p{groundToCamera(ground, s.camera_height_mm, s.inclination_deg)};
    std::vector<cv::Point2d> l, r;
    cv::projectPoints(p, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), c.M1, c.D1, l);
    cv::Mat rvec;
    cv::Rodrigues(c.R, rvec);
    cv::projectPoints(p, rvec, c.T, c.M2, c.D2, r);
    left = l[0];
    right = r[0];
}

class MarkerProjection : public ::testing::TestWithParam<bool> {};

// Test (1): the centroid of a small bright marker lands where the pinhole model says.
// Markers are 100 mm squares (5 to 10 px): an intensity centroid of an area-sampled blob
// is itself off by up to a few hundredths of a pixel when its edges cut pixels
// unevenly, and that bias shrinks with the blob's width.
TEST_P(MarkerProjection, CentroidWithinATenthOfAPixel) {
    const RigSettings s = GetParam() ? imperfectRig() : RigSettings{};
    const std::vector<cv::Point3d> centres{{0, 5000, 1500}, {450, 6000, 1900}, {-700, 4000, 1000}, {900, 8000, 1200},
                                           {-300, 7000, 2100}};
    const sim::Scene scene = markerScene(centres, 100);
    const sim::StereoRig rig(s);
    const sim::RenderedFrame f = sim::Renderer(rig, exact(8)).render(scene, {}, 0);
    const StereoCalibration c = StereoCalibration::fromYaml(rig.calibrationYaml(), "sim calibration");
    double worst = 0;
    for (const cv::Point3d &g : centres) {
        cv::Point2d l, r;
        projectWithCalibration(c, s, g, l, r);
        const cv::Point2d cl = centroidNear(f.left, l, 9), cr = centroidNear(f.right, r, 9);
        EXPECT_LT(cv::norm(cl - l), 0.1) << "left: marker at " << g << " expected " << l << " got " << cl;
        EXPECT_LT(cv::norm(cr - r), 0.1) << "right: marker at " << g << " expected " << r << " got " << cr;
        worst = std::max({worst, cv::norm(cl - l), cv::norm(cr - r)});
    }
    std::cout << "[ figures  ] " << (GetParam() ? "imperfect" : "ideal") << " rig: largest centroid error " << worst
              << " px over " << 2 * centres.size() << " marker images\n";
    RecordProperty("largest_centroid_error_px", std::to_string(worst));
}

INSTANTIATE_TEST_SUITE_P(Rigs, MarkerProjection, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool> &i) { return i.param ? "Imperfect" : "Ideal"; });

// Test (2): the same seed gives the same bytes (whatever the thread count), another
// seed other noise of the stated strength.
TEST(SimNoise, SeededAndDeterministic) {
    const sim::Scene scene = sim::Scene::builtIn();
    const sim::StereoRig rig(RigSettings{});
    RenderSettings a;
    a.seed = 7;
    const sim::RenderedFrame f1 = sim::Renderer(rig, a).render(scene, {}, 0);
    const int threads = cv::getNumThreads();
    cv::setNumThreads(1);
    const sim::RenderedFrame f2 = sim::Renderer(rig, a).render(scene, {}, 0);
    cv::setNumThreads(threads);
    EXPECT_EQ(cv::norm(f1.left, f2.left, cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(f1.right, f2.right, cv::NORM_INF), 0);

    RenderSettings b = a;
    b.seed = 8;
    const sim::RenderedFrame g = sim::Renderer(rig, b).render(scene, {}, 0);
    cv::Mat diff;
    cv::subtract(f1.left, g.left, diff, cv::noArray(), CV_32F);
    cv::Scalar mean, sd;
    cv::meanStdDev(diff, mean, sd);
    // Two independent draws of sigma = 2: their difference has sigma 2 * sqrt(2).
    EXPECT_NEAR(sd[0], 2.0 * std::sqrt(2.0), 0.3);
    EXPECT_NEAR(mean[0], 0.0, 0.05);
    // Another frame of the same seed: other noise too.
    const sim::RenderedFrame h = sim::Renderer(rig, a).render(scene, {}, 1);
    EXPECT_GT(cv::norm(f1.left, h.left, cv::NORM_L1), 0);

    RenderSettings quiet = a;
    quiet.noise_sigma = 0;
    RenderSettings quiet2 = quiet;
    quiet2.seed = 8;
    EXPECT_EQ(cv::norm(sim::Renderer(rig, quiet).render(scene, {}, 0).left,
                       sim::Renderer(rig, quiet2).render(scene, {}, 0).left, cv::NORM_INF),
              0);
}

// Test (3): with distortion and a misaligned right imager, rectifying with the sim's
// own calibration brings corresponding points onto the same row within 0.5 px, and
// their column difference is the ground truth disparity.
TEST(SimCalibration, RectificationAlignsRows) {
    const RigSettings s = imperfectRig();
    std::vector<cv::Point3d> centres;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 3; ++j)
            centres.emplace_back(-900 + 600 * i + 50 * j, 3000 + 1500 * j + 300 * i, 900 + 450 * j + 120 * i);
    const sim::Scene scene = markerScene(centres, 60);
    const sim::StereoRig rig(s);
    const sim::RenderedFrame f = sim::Renderer(rig, exact(6)).render(scene, {}, 0);
    const StereoCalibration c = StereoCalibration::fromYaml(rig.calibrationYaml(), "sim calibration");
    ASSERT_FALSE(c.rectified);

    auto rectify = [&](const cv::Mat &image, const cv::Mat &M, const cv::Mat &D, const cv::Mat &R, const cv::Mat &P) {
        cv::Mat mx, my, out;
        cv::initUndistortRectifyMap(M, D, R, P, c.image_size, CV_32FC1, mx, my);
        cv::remap(image, out, mx, my, cv::INTER_LINEAR);
        return out;
    };
    // Measured row difference of each marker in a rectified pair.
    auto rowErrors = [&](const cv::Mat &left, const cv::Mat &right, const cv::Mat &R1, const cv::Mat &P1,
                         std::vector<double> *disparityErrors) {
        std::vector<double> errors;
        for (const cv::Point3d &g : centres) {
            const std::vector<cv::Point3d> p{groundToCamera(g, s.camera_height_mm, s.inclination_deg)};
            std::vector<cv::Point2d> at;
            cv::Mat r1;
            cv::Rodrigues(R1, r1);
            cv::projectPoints(p, r1, cv::Vec3d(0, 0, 0), P1(cv::Rect(0, 0, 3, 3)), cv::noArray(), at);
            const cv::Point2d l = centroidNear(left, at[0], 7);
            const float d = f.gt_disparity.at<float>(cvRound(at[0].y), cvRound(at[0].x));
            const cv::Point2d r = centroidNear(right, at[0] - cv::Point2d(d, 0), 7);
            errors.push_back(std::abs(l.y - r.y));
            if (disparityErrors) disparityErrors->push_back(std::abs((l.x - r.x) - d));
        }
        return errors;
    };

    std::vector<double> disparityErrors;
    const std::vector<double> rows = rowErrors(rectify(f.left, c.M1, c.D1, c.R1, c.P1),
                                               rectify(f.right, c.M2, c.D2, c.R2, c.P2), c.R1, c.P1, &disparityErrors);
    const double worstRow = *std::max_element(rows.begin(), rows.end());
    const double worstDisparity = *std::max_element(disparityErrors.begin(), disparityErrors.end());
    EXPECT_LT(worstRow, 0.5);
    EXPECT_LT(worstDisparity, 0.5);
    std::cout << "[ figures  ] rectified with the sim's calibration: largest row error " << worstRow
              << " px, largest disparity error against gt_disparity " << worstDisparity << " px (" << centres.size()
              << " markers)\n";
    RecordProperty("largest_row_error_px", std::to_string(worstRow));

    // Control: rectified as if the head were ideal, the rows do not meet.
    const StereoCalibration ideal = StereoCalibration::ideal(c.image_size, s.focalLengthPx(), s.baseline_mm);
    const std::vector<double> naive =
        rowErrors(rectify(f.left, ideal.M1, ideal.D1, ideal.R1, ideal.P1),
                  rectify(f.right, ideal.M2, ideal.D2, ideal.R2, ideal.P2), ideal.R1, ideal.P1, nullptr);
    EXPECT_GT(*std::max_element(naive.begin(), naive.end()), 1.0);
}

TEST(SimCalibration, IdealRigIsRectifiedWithTheNominalFocalLength) {
    const sim::StereoRig rig(RigSettings{});
    const StereoCalibration c = StereoCalibration::fromYaml(rig.calibrationYaml(), "sim calibration");
    EXPECT_TRUE(c.rectified);
    EXPECT_NEAR(c.focalLengthPx(), 8.0 * 1000 / 20.8, 1e-9);
    EXPECT_NEAR(c.baselineMm(), 150.0, 1e-9);
    EXPECT_NEAR(c.T.at<double>(0), -150.0, 1e-9);
    EXPECT_NEAR(c.M1.at<double>(0, 2), 159.5, 1e-12);
    EXPECT_NEAR(c.M1.at<double>(1, 2), 119.5, 1e-12);
}

// The panel face is a plane at a known range: its truth is f B / R exactly.
TEST(SimGroundTruth, PanelFaceDisparityIsFocalTimesBaselineOverRange) {
    const sim::Scene scene = sim::Scene::builtIn();
    const sim::StereoRig rig(RigSettings{});
    const sim::RenderedFrame f = sim::Renderer(rig, RenderSettings{}).render(scene, {}, 0);
    const double expected = 8.0 * 1000 / 20.8 * 150 / 6000; // 9.615 px
    const uint16_t panel = scene.objects.at(0).id;
    int face = 0;
    for (int v = 0; v < f.gt_disparity.rows; ++v)
        for (int u = 0; u < f.gt_disparity.cols; ++u) {
            if (f.gt_object_id.at<uint16_t>(v, u) != panel) continue;
            ASSERT_EQ(f.gt_valid.at<uint8_t>(v, u), 255);
            const float d = f.gt_disparity.at<float>(v, u), z = f.gt_depth.at<float>(v, u);
            EXPECT_NEAR(d, 8.0 * 1000 / 20.8 * 150 / z, 1e-3);
            if (std::abs(z - 6000) < 1e-3) {
                ++face;
                EXPECT_NEAR(d, expected, 1e-3);
            }
        }
    // The nine cube faces: 9 * (500 mm * f / 6000 mm)^2 pixels, give or take their edges.
    EXPECT_NEAR(face, 9 * std::pow(500 * 384.615 / 6000, 2), 200);
    // Sky above the horizon row, ground below it.
    EXPECT_EQ(f.gt_valid.at<uint8_t>(0, 0), 0);
    EXPECT_EQ(f.gt_disparity.at<float>(0, 0), -1.0f);
    EXPECT_EQ(f.gt_object_id.at<uint16_t>(239, 0), sim::Scene::kGroundId);
    // Ground row v at theta = 0: Z = hc f / (v - cy).
    EXPECT_NEAR(f.gt_depth.at<float>(239, 0), 1500 * 384.615385 / (239 - 119.5), 0.5);
}

// Inclination as METHOD.md defines it: points of the ground truth, taken back to the
// ground frame with Eq. 1, lie on the ground (Z = 0) or on the panel's face (Y = 6000).
TEST(SimGroundTruth, InclinedRigFollowsEquationOne) {
    RigSettings s;
    s.inclination_deg = 10;
    const sim::Scene scene = sim::Scene::builtIn();
    const sim::StereoRig rig(s);
    const sim::RenderedFrame f = sim::Renderer(rig, RenderSettings{}).render(scene, {}, 0);
    const double th = 10 * CV_PI / 180, fpx = s.focalLengthPx(), cx = 159.5, cy = 119.5;
    const uint16_t panel = scene.objects.at(0).id;
    int ground = 0, face = 0;
    for (int v = 0; v < f.gt_depth.rows; ++v)
        for (int u = 0; u < f.gt_depth.cols; ++u) {
            const double zc = f.gt_depth.at<float>(v, u);
            if (zc <= 0) continue;
            const double xc = (u - cx) / fpx * zc, yc = (v - cy) / fpx * zc;
            const double Y = zc * std::cos(th) - yc * std::sin(th), Z = 1500 - zc * std::sin(th) - yc * std::cos(th); // Eq. 1
            const uint16_t id = f.gt_object_id.at<uint16_t>(v, u);
            if (id == sim::Scene::kGroundId) {
                EXPECT_NEAR(Z, 0, 1e-3 * zc) << "ground pixel " << u << "," << v;
                ++ground;
            } else if (id == panel && std::abs(Y - 6000) < 1) {
                EXPECT_GE(Z, -1e-6);
                EXPECT_LE(Z, 2000 + 1e-6);
                EXPECT_LE(std::abs(xc), 1250 + 1e-6);
                ++face;
            }
        }
    EXPECT_GT(ground, 10000);
    EXPECT_GT(face, 500);
}

TEST(SimScene, RangeMovesTheMainObjectAndMetadataFollowsTheRig) {
    sim::Scene scene = sim::Scene::builtIn();
    scene.placeMainObjectAtRange(12000);
    const sim::StereoRig rig(RigSettings{});
    sim::RigPose pose;
    pose.forward_mm = 1000;
    const std::string yaml = sim::frameMetadata(scene, rig, pose, 3);
    EXPECT_NE(yaml.find("range_mm: 11000"), std::string::npos) << yaml;
    EXPECT_NE(yaml.find("width_mm: 2500"), std::string::npos) << yaml;
    EXPECT_NE(yaml.find("height_mm: 2000"), std::string::npos) << yaml;
    EXPECT_NE(yaml.find("center_mm: [0, 11250, 1000]"), std::string::npos) << yaml;
}

// The message of the error reading `yaml` as a scene gives ("" if none).
std::string sceneError(const std::string &yaml) {
    try {
        sim::Scene::fromYaml(yaml, "scene.yaml", "");
    } catch (const sim::SceneError &e) {
        return e.what();
    }
    return "";
}

TEST(SimScene, ErrorsNameFileLineAndKey) {
    const auto error = sceneError;
    std::string e = error("name: x\nobjects:\n  - {name: a, type: box, center_mm: [0, 1, 2], size_mm: [1, 1]}\n");
    EXPECT_NE(e.find("scene.yaml:3:"), std::string::npos) << e;
    EXPECT_NE(e.find("size_mm"), std::string::npos) << e;
    e = error("name: x\nobjects:\n  - {name: a, type: box, center_mm: [0, 1, 2], size_mm: [1, 1, 1], colour: 3}\n");
    EXPECT_NE(e.find("unknown key 'colour'"), std::string::npos) << e;
    e = error("objects:\n  - {name: a, type: pyramid}\n");
    EXPECT_NE(e.find("type 'pyramid'"), std::string::npos) << e;
    e = error("ground: {texture: {type: noise, scale_mm: -4}}\n");
    EXPECT_NE(e.find("scale_mm = -4: expected a value > 0"), std::string::npos) << e;
    e = error("main_object: tree\nobjects: []\n");
    EXPECT_NE(e.find("no object named 'tree'"), std::string::npos) << e;
}

// Issue 24: a 100000 x 100000 cube_matrix hung while 1e10 boxes were built; the work is
// bounded up front, with the key and the number allowed.
TEST(SimScene, PrimitiveCountIsBoundedBeforeBuilding) {
    const auto error = sceneError;
    EXPECT_EQ(error("objects:\n  - {name: p, type: cube_matrix, cols: 100000, rows: 100000}\n"),
              "scene.yaml:2:5: object 'p': cols x rows = 100000 x 100000 asks for 10000000000 primitives; a scene "
              "holds at most 10000 (0 already used)");
    EXPECT_EQ(error("objects:\n  - {name: p, type: cube_matrix, cols: 100, rows: 99}\n"
                    "  - {name: t, type: tree, base_mm: [0, 9000, 0], crown_spheres: 99}\n"),
              "scene.yaml:3:65: object 't': crown_spheres = 99 (+ trunk and core) asks for 101 primitives; a scene "
              "holds at most 10000 (9900 already used)");
    EXPECT_EQ(error("objects:\n  - {name: p, type: cube_matrix, cols: 100, rows: 100}\n"), "");
}

// An image texture tiles a face with its top row up: a picture red above, blue below,
// on a box facing the rig, seen in colour.
TEST(SimScene, ImageTextureAppearsUprightOnAFace) {
    TempDir dir;
    cv::Mat picture(64, 64, CV_8UC3, cv::Scalar(255, 0, 0)); // BGR: blue
    picture(cv::Rect(0, 0, 64, 32)).setTo(cv::Scalar(0, 0, 255)); // top half red
    ASSERT_TRUE(cv::imwrite(dir.str("picture.png"), picture));
    const sim::Scene scene = sim::Scene::fromYaml(
        "ground: none\nlight: {ambient: 1}\nobjects:\n"
        "  - {name: sign, type: box, center_mm: [0, 5000, 1500], size_mm: [1000, 10, 1000],\n"
        "     texture: {type: image, file: picture.png, size_mm: [1000, 1000]}}\n",
        "sign.yaml", dir.str());
    RenderSettings colour = exact(2);
    colour.color = true;
    const sim::StereoRig rig(RigSettings{});
    const sim::RenderedFrame f = sim::Renderer(rig, colour).render(scene, {}, 0);
    // The sign spans 1000 mm * 384.6 / 5000 mm = 77 px around the image centre.
    const cv::Vec3b above = f.left.at<cv::Vec3b>(100, 160), below = f.left.at<cv::Vec3b>(140, 160);
    EXPECT_GT(above[2], 200);
    EXPECT_LT(above[0], 50);
    EXPECT_GT(below[0], 200);
    EXPECT_LT(below[2], 50);
}

TEST(SimScene, SceneFilesOfTheRepositoryLoad) {
    const sim::Scene e1 = sim::Scene::load(std::string(BINOCLE_SOURCE_DIR) + "/configs/scenes/e1_panel.yaml");
    const sim::Scene e2 = sim::Scene::load(std::string(BINOCLE_SOURCE_DIR) + "/configs/scenes/e2_tree.yaml");
    ASSERT_EQ(e1.objects.size(), 1u);
    EXPECT_EQ(e1.objects[0].parts.size(), 9u);
    EXPECT_NEAR(e1.objects[0].boundsMax.x() - e1.objects[0].boundsMin.x(), 2500, 1e-9);
    EXPECT_NEAR(e1.objects[0].boundsMax.z() - e1.objects[0].boundsMin.z(), 2000, 1e-9);
    EXPECT_NEAR(e1.objects[0].boundsMin.y(), 6000, 1e-9);
    ASSERT_GE(e2.findObject("marker"), 0);
    EXPECT_EQ(e2.objects[static_cast<size_t>(e2.mainObject)].name, "marker");
    ASSERT_GE(e2.findObject("tree"), 0);
    // The built-in scene is the E1 file.
    EXPECT_EQ(sim::Scene::builtIn().objects[0].parts.size(), 9u);
}

} // namespace
} // namespace binocle::test
