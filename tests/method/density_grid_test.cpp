// SPDX-License-Identifier: MIT
// Density grids: binning into top, front and side views, object localisation, pictures.
#include "method/density_grid.hpp"
#include "method/density_render.hpp"
#include "synthetic_cloud.hpp"
#include "../common/test_util.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace binocle::test {
namespace {

using namespace binocle::method;

TEST(DensityGrid, BinsPointsIntoTheThreeViews) {
    GridSpec spec;
    spec.cell_mm = 100;
    spec.x = {-1000, 1000};
    spec.y = {0, 2000};
    spec.z = {0, 1000};
    const std::vector<float> xyz = {
        -950, 50, 50,    // first cell of every view
        -950, 60, 70,    // same cells
        150, 1050, 550,  // top (col 11, row 10), front (col 11, row 5), side (col 10, row 5)
        5000, 100, 100,  // outside X: in no view
        NAN, 100, 100,   // not finite: in no view
    };
    const DensityGrids g = binCloud(CloudView(xyz), spec);
    EXPECT_EQ(g.top.cols(), 20);
    EXPECT_EQ(g.top.rows(), 20);
    EXPECT_EQ(g.front.cols(), 20);
    EXPECT_EQ(g.front.rows(), 10);
    EXPECT_EQ(g.side.cols(), 20);
    EXPECT_EQ(g.side.rows(), 10);
    EXPECT_EQ(g.top.count(0, 0), 2);
    EXPECT_EQ(g.front.count(0, 0), 2);
    EXPECT_EQ(g.side.count(0, 0), 2);
    EXPECT_EQ(g.top.count(10, 11), 1);
    EXPECT_EQ(g.front.count(5, 11), 1);
    EXPECT_EQ(g.side.count(5, 10), 1);
    EXPECT_EQ(g.top.total(), 3);
    EXPECT_EQ(g.front.total(), 3);
    EXPECT_EQ(g.side.total(), 3);
    EXPECT_EQ(cv::countNonZero(g.top.occupied(2)), 1);
    const DensityView above = binView(CloudView(xyz), View::Front, spec, [](float, float, float z) { return z > 100; });
    EXPECT_EQ(above.total(), 1);
}

TEST(DensityGrid, RefusesABadSpec) {
    const auto why = [](const GridSpec &spec) -> std::string {
        try {
            spec.validate();
        } catch (const std::invalid_argument &e) {
            return e.what();
        }
        return "(accepted)";
    };
    GridSpec spec;
    spec.cell_mm = 0;
    EXPECT_THROW(spec.validate(), std::invalid_argument);
    spec.cell_mm = 100;
    spec.x = {10, -10};
    EXPECT_NE(why(spec).find("X extent"), std::string::npos) << why(spec);
    // 4.3e11 mm of X in 100 mm cells: 4.3e9 cells, past an int; counted before any cast.
    spec.x = {-2.15e11, 2.15e11};
    EXPECT_NE(why(spec).find("top-view (X by Y) cells: expected at most 6.4e+07"), std::string::npos) << why(spec);
    // The front and side views count too (X by Z, Y by Z), not only the top view.
    spec.x = {-6000, 6000};
    spec.z = {0, 5e9};
    EXPECT_NE(why(spec).find("front-view (X by Z) cells"), std::string::npos) << why(spec);
}

// The E1 panel seen from the top: three columns of cubes, 1 m apart, at the panel's range.
TEST(ObjectLocalisation, FindsThePanelsThreeColumns) {
    const std::vector<float> xyz = panelScene();
    GridSpec spec;
    const std::vector<LocalisedObject> objects = localiseObjects(CloudView(xyz), spec);
    ASSERT_EQ(objects.size(), 3u) << objectsJson(objects);
    std::vector<double> xs;
    for (const LocalisedObject &o : objects) {
        xs.push_back(o.center_x_mm);
        EXPECT_NEAR(o.range_mm, 6000, 5);
        EXPECT_NEAR(o.width_mm, 500, 25) << objectsJson(objects);
        EXPECT_NEAR(o.height_mm, 2000, 30) << objectsJson(objects);
        EXPECT_TRUE(o.on_ground);
        EXPECT_NEAR(o.centroid_y_mm, 6000, 5);
    }
    std::sort(xs.begin(), xs.end());
    EXPECT_NEAR(xs[0], -1000, 15);
    EXPECT_NEAR(xs[1], 0, 15);
    EXPECT_NEAR(xs[2], 1000, 15);
}

TEST(ObjectLocalisation, BoxesAtTheirPlaces) {
    CloudBuilder b(11);
    // A 0.5 m box at X = -1000, near face at 6000 (front and top faces seen), and a
    // 1 m x 1 m x 1.5 m floating box at X = 2000, 9000 .. 10000, from 500 to 1500 mm high.
    b.frontFace(-1250, -750, 0, 500, 6000, 10, 3);
    b.topFace(-1250, -750, 6000, 6500, 500, 20, 3);
    b.frontFace(1500, 2500, 500, 1500, 9000, 15, 3);
    b.ground(-5000, 5000, 1000, 15000, 100, 5);
    b.outliers(30);
    GridSpec spec;
    const std::vector<LocalisedObject> objects = localiseObjects(CloudView(b.xyz), spec);
    ASSERT_EQ(objects.size(), 2u) << objectsJson(objects);
    const LocalisedObject &small = objects[0].center_x_mm < 0 ? objects[0] : objects[1];
    const LocalisedObject &floating = objects[0].center_x_mm < 0 ? objects[1] : objects[0];
    EXPECT_NEAR(small.center_x_mm, -1000, 15);
    EXPECT_NEAR(small.range_mm, 6000, 30); // the front face dominates its points
    EXPECT_NEAR(small.y_min_mm, 6000, 30);
    EXPECT_NEAR(small.y_max_mm, 6500, 30);
    EXPECT_NEAR(small.height_mm, 500, 30);
    EXPECT_NEAR(floating.center_x_mm, 2000, 15);
    EXPECT_NEAR(floating.width_mm, 1000, 25);
    EXPECT_NEAR(floating.range_mm, 9000, 5);
    EXPECT_FALSE(floating.on_ground);
    EXPECT_NEAR(floating.z_min_mm, 500, 30);
    EXPECT_NEAR(floating.z_max_mm, 1500, 30);
    EXPECT_NEAR(floating.height_mm, 1000, 40);
    const std::string json = objectsJson(objects);
    EXPECT_NE(json.find("\"center_x_mm\""), std::string::npos);
    EXPECT_EQ(objectsJson({}), "[]");
}

TEST(RefineEdges, AreaEquivalentEdgesAreSubCell) {
    // Uniform points from 123 to 877 mm on 100 mm cells: occupied cells 100 .. 900.
    std::vector<float> v;
    for (double x = 123; x < 877; x += 0.5) v.push_back(static_cast<float>(x));
    const Extent e = refineEdges(v, {100, 900}, 100);
    EXPECT_NEAR(e.min_mm, 123, 0.6);
    EXPECT_NEAR(e.max_mm, 877, 0.6);
    // Runs shorter than three cells keep their cell edges.
    const Extent short_ = refineEdges(v, {100, 250}, 100);
    EXPECT_DOUBLE_EQ(short_.min_mm, 100);
    EXPECT_DOUBLE_EQ(short_.max_mm, 250);
}

TEST(DensityRender, DrawsAReadablePictureAndWritesItWhole) {
    const std::vector<float> xyz = panelScene();
    GridSpec spec;
    const DensityView front = binView(CloudView(xyz), View::Front, spec);
    RenderOptions options;
    options.density_threshold = spec.density_threshold;
    options.overlays.push_back({{-1250, 1250}, {0, 2000}, "panel", {40, 40, 220}});
    const cv::Mat img = renderDensityView(front, options);
    ASSERT_EQ(img.type(), CV_8UC3);
    EXPECT_GT(img.cols, front.cols());
    EXPECT_GT(img.rows, front.rows());
    cv::Mat gray;
    cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
    EXPECT_GT(cv::countNonZero(gray < 200), 1000); // cells, axes, labels

    TempDir dir;
    const std::string path = dir.str("front.png");
    writePngAtomic(path, img);
    const cv::Mat back = cv::imread(path, cv::IMREAD_COLOR);
    ASSERT_FALSE(back.empty());
    EXPECT_EQ(back.size(), img.size());
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 1);
    EXPECT_THROW(writePngAtomic(dir.str("no/such/folder/x.png"), img), std::runtime_error);

    // A symlink planted under the name the writer once used (PATH.tmp-<pid>) is never
    // followed: its target stays untouched, and the picture still lands whole.
    const std::string target = dir.str("target.txt");
    writeText(target, "untouched");
    const std::string planted = path + ".tmp-" + std::to_string(::getpid());
    std::filesystem::create_symlink(target, planted);
    writePngAtomic(path, img);
    std::ifstream in(target);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "untouched");
    EXPECT_TRUE(std::filesystem::is_symlink(planted));
    EXPECT_EQ(cv::imread(path, cv::IMREAD_COLOR).size(), img.size());

    // The top view of an empty cloud is still a picture (axes, no cells).
    const cv::Mat empty = renderDensityView(binView(CloudView(), View::Top, spec));
    EXPECT_FALSE(empty.empty());
}

} // namespace
} // namespace binocle::test
