// SPDX-License-Identifier: MIT
// Eq. 1 against hand-computed points, and the E2 indicators: ground plane fit (offset,
// recovered inclination, angular error) and the centre-of-coordinates offset.
#include "method/ground_plane.hpp"
#include "synthetic_cloud.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace binocle::test {
namespace {

using namespace binocle::method;

// Eq. 1 with hc = 1500 mm: hand-computed (cos 10 deg = 0.984807753, sin 10 deg = 0.173648178).
TEST(Eq1, HandComputedPointsAtZeroAndTenDegrees) {
    const method::GroundFrame level(1500, 0), tilted(1500, 10);
    auto expectPoint = [](const std::array<double, 3> &g, double x, double y, double z) {
        EXPECT_NEAR(g[0], x, 1e-5);
        EXPECT_NEAR(g[1], y, 1e-5);
        EXPECT_NEAR(g[2], z, 1e-5);
    };
    expectPoint(level.toGround(0, 0, 6000), 0, 6000, 1500);         // on the axis: Y = d, Z = hc
    expectPoint(level.toGround(250, 1500, 6000), 250, 6000, 0);     // on the ground, 1.5 m below the axis
    expectPoint(tilted.toGround(0, 0, 6000), 0, 5908.846518, 458.110934); // Y = d cos, Z = hc - d sin
    // Y = 5000 cos + 200 sin = 4924.038765 + 34.729636; Z = 1500 - 5000 sin + 200 cos = 1500 - 868.240890 + 196.961551
    expectPoint(tilted.toGround(100, -200, 5000), 100, 4958.768401, 828.720661);
}

TEST(GroundPlane, LevelGroundHasNoOffsetAndNoTilt) {
    const std::vector<float> xyz = groundSeenWithInclination(1500, 0, 0, 10);
    const GroundPlane g = fitGroundPlane(CloudView(xyz));
    ASSERT_TRUE(g.found);
    EXPECT_NEAR(g.offset_mm, 0, 3);
    EXPECT_NEAR(g.pitch_deg, 0, 0.05);
    EXPECT_NEAR(g.roll_deg, 0, 0.05);
    EXPECT_NEAR(recoveredInclinationDeg(0, g), 0, 0.05);
    EXPECT_NEAR(g.rms_mm, 10, 3);
}

// A camera pitched 8 deg down whose cloud is moved with Eq. 1 at 0 deg (inclination not
// set) or at 5 deg (set wrong): the fitted ground gives the true 8 deg back.
TEST(GroundPlane, RecoversTheTiltWithinAFifthOfADegree) {
    for (double applied : {0.0, 5.0, 8.0}) {
        const std::vector<float> xyz = groundSeenWithInclination(1500, 8, applied, 15);
        const GroundPlane g = fitGroundPlane(CloudView(xyz));
        ASSERT_TRUE(g.found) << applied;
        EXPECT_NEAR(g.pitch_deg, 8 - applied, 0.2) << applied;
        EXPECT_NEAR(recoveredInclinationDeg(applied, g), 8, 0.2) << applied;
        EXPECT_NEAR(recoveredInclinationDeg(applied, g) - 8, 0, 0.2) << "angular error, applied " << applied;
    }
}

TEST(GroundPlane, IgnoresThePanelAndOutliers) {
    std::vector<float> xyz = groundSeenWithInclination(1500, 10, 10, 10);
    const std::vector<float> panel = panelScene(); // vertical faces, a flat ground and outliers
    xyz.insert(xyz.end(), panel.begin(), panel.end());
    const GroundPlane g = fitGroundPlane(CloudView(xyz));
    ASSERT_TRUE(g.found);
    EXPECT_NEAR(g.pitch_deg, 0, 0.2);
    EXPECT_NEAR(g.offset_mm, 0, 5);
}

TEST(GroundPlane, CameraHeightErrorShowsAsGroundOffset) {
    std::vector<float> xyz = groundSeenWithInclination(1500, 0, 0, 5);
    for (size_t i = 2; i < xyz.size(); i += 3) xyz[i] += 120; // the transform assumed hc 120 mm too high
    const GroundPlane g = fitGroundPlane(CloudView(xyz));
    ASSERT_TRUE(g.found);
    EXPECT_NEAR(g.offset_mm, 120, 3);
    EXPECT_NEAR(g.heightAt(1000, 10000), 120, 3);
}

TEST(GroundPlane, NothingToFit) {
    const GroundPlane g = fitGroundPlane(CloudView());
    EXPECT_FALSE(g.found);
    EXPECT_TRUE(std::isnan(recoveredInclinationDeg(0, g)));
    // Only a vertical wall: no plane is flat enough to be ground.
    CloudBuilder b(2);
    b.frontFace(-2000, 2000, 0, 3000, 8000, 50, 2);
    EXPECT_FALSE(fitGroundPlane(CloudView(b.xyz)).found);
}

TEST(ObjectOffset, LateralAndRangeOffsetsOfAKnownObject) {
    CloudBuilder b(9);
    // The marker of the E2 scene, seen 60 mm to the right and 90 mm farther than it is.
    b.frontFace(-1250 + 60, -750 + 60, 0, 500, 6000 + 90, 10, 3);
    b.ground(-5000, 5000, 1000, 15000, 100, 5);
    GridSpec spec;
    const std::vector<LocalisedObject> objects = localiseObjects(CloudView(b.xyz), spec);
    KnownObject marker;
    marker.name = "marker";
    marker.center_mm[0] = -1000;
    marker.center_mm[1] = 6250;
    marker.center_mm[2] = 250;
    marker.size_mm[0] = marker.size_mm[1] = marker.size_mm[2] = 500;
    const ObjectOffset off = objectOffset(objects, marker, 1500);
    ASSERT_TRUE(off.found);
    EXPECT_NEAR(off.lateral_mm, 60, 10);
    EXPECT_NEAR(off.range_mm, 90, 5);
    EXPECT_NEAR(off.true_range_mm, 6000, 1e-9);
    EXPECT_NEAR(off.distance_mm, std::hypot(60, 90), 10);
    EXPECT_FALSE(objectOffset(objects, marker, 50).found); // farther than allowed
}

// A smeared cloud joins the marker to a big object behind it in the top view: the
// object is still read where it should be.
TEST(ObjectOffset, KnownObjectReadWhereItShouldBe) {
    CloudBuilder b(12);
    b.frontFace(-1250 + 60, -750 + 60, 0, 500, 6000 + 90, 10, 3);  // the marker, offset
    b.topFace(-1250 + 60, -750 + 60, 6090, 6590, 500, 20, 3);       // its top
    b.frontFace(600, 1800, 0, 3000, 9000, 20, 5);                   // a trunk and crown behind
    b.topFace(-1000, 1200, 6600, 9000, 300, 30, 5);                  // smear joining them (a sheet)
    b.ground(-5000, 5000, 1000, 15000, 100, 5);
    KnownObject marker;
    marker.center_mm[0] = -1000;
    marker.center_mm[1] = 6250;
    marker.center_mm[2] = 250;
    marker.size_mm[0] = marker.size_mm[1] = marker.size_mm[2] = 500;
    GridSpec spec;
    const std::vector<LocalisedObject> objects = localiseObjects(CloudView(b.xyz), spec);
    EXPECT_FALSE(objectOffset(objects, marker, 300).found); // merged with the rest in the top view
    PanelReadingOptions o;
    const ObjectOffset off = locateKnownObject(CloudView(b.xyz), marker, o, 500);
    ASSERT_TRUE(off.found);
    EXPECT_NEAR(off.lateral_mm, 60, 10);
    EXPECT_NEAR(off.range_mm, 90, 5);
    SyntheticScene empty;
    empty.panel = false;
    EXPECT_FALSE(locateKnownObject(CloudView(panelScene(empty)), marker, o, 500).found);
}

} // namespace
} // namespace binocle::test
