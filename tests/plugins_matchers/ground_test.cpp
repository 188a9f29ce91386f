// SPDX-License-Identifier: MIT
// ground plugin: METHOD.md Eq. 1 (camera frame -> ground frame), directly and through the host.
#include "method/ground_frame.hpp"
#include "plugin_fixtures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace binocle::test {
namespace {

constexpr double kTol = 1e-3; // mm, float storage of points of a few metres

struct Case {
    double xc, yc, zc;   // camera frame, mm
    double x, y, z;      // ground frame, hand-computed, mm
};

// hc = 1500 mm. theta = 10 deg: cos = 0.984807753, sin = 0.173648178.
const Case kLevel[] = {
    {0, 0, 6000, 0, 6000, 1500},         // on the optical axis: Y = d, Z = hc
    {100, -200, 5000, 100, 5000, 1700},  // 200 mm above the axis
    {-300, 1500, 6000, -300, 6000, 0},   // on the ground
};
const Case kTilted[] = {
    {0, 0, 6000, 0, 5908.846518, 458.110934},      // Y = d cos, Z = hc - d sin
    {100, -200, 5000, 100, 4958.768401, 828.720662}, // Y = 4924.038765 + 34.729636, Z = 1500 - 868.240890 + 196.961551
    {0, 1000, 0, 0, -173.648178, 515.192247},      // straight below the centre, 1 m: Y = -sin, Z = hc - cos
};

TEST(GroundFrame, Eq1AtZeroAndTenDegrees) {
    for (const Case &c : kLevel) {
        const auto g = method::GroundFrame(1500, 0).toGround(c.xc, c.yc, c.zc);
        EXPECT_NEAR(g[0], c.x, 1e-9);
        EXPECT_NEAR(g[1], c.y, 1e-9);
        EXPECT_NEAR(g[2], c.z, 1e-9);
    }
    for (const Case &c : kTilted) {
        const auto g = method::GroundFrame(1500, 10).toGround(c.xc, c.yc, c.zc);
        EXPECT_NEAR(g[0], c.x, 1e-5);
        EXPECT_NEAR(g[1], c.y, 1e-5);
        EXPECT_NEAR(g[2], c.z, 1e-5);
    }
}

CloudTransform makeGround(const std::string &yaml) {
    const PluginRecord &record = builtPlugins().require("ground", BINOCLE_KIND_CLOUD_TRANSFORM);
    return CloudTransform(record, paramsFromYaml(record, yaml));
}

// The cloud holds `cases` in the camera frame; rgb and pixel ride along untouched.
struct TestCloud {
    std::vector<float> xyz;
    std::vector<uint8_t> rgb;
    std::vector<int32_t> pixel;
    binocle_cloud cloud{};
    template <size_t N>
    explicit TestCloud(const Case (&cases)[N]) {
        for (const Case &c : cases) xyz.insert(xyz.end(), {float(c.xc), float(c.yc), float(c.zc)});
        for (size_t i = 0; i < N; ++i) {
            rgb.insert(rgb.end(), {uint8_t(i), 7, 9});
            pixel.push_back(int32_t(100 + i));
        }
        cloud.count = N;
        cloud.xyz = xyz.data();
        cloud.rgb = rgb.data();
        cloud.pixel = pixel.data();
        cloud.image_width = 640;
        cloud.image_height = 480;
        cloud.frame = BINOCLE_FRAME_CAMERA;
    }
};

template <size_t N>
void expectGround(const TestCloud &t, const Case (&cases)[N]) {
    ASSERT_EQ(t.cloud.count, int64_t(N));
    EXPECT_EQ(t.cloud.frame, BINOCLE_FRAME_GROUND);
    for (size_t i = 0; i < N; ++i) {
        EXPECT_NEAR(t.xyz[3 * i + 0], cases[i].x, kTol) << "point " << i;
        EXPECT_NEAR(t.xyz[3 * i + 1], cases[i].y, kTol) << "point " << i;
        EXPECT_NEAR(t.xyz[3 * i + 2], cases[i].z, kTol) << "point " << i;
        EXPECT_EQ(t.rgb[3 * i], uint8_t(i));
        EXPECT_EQ(t.pixel[i], int32_t(100 + i));
    }
}

TEST(GroundPlugin, LevelCamera) {
    TestCloud t(kLevel);
    makeGround("{camera_height_mm: 1500, inclination_deg: 0}").apply(t.cloud);
    expectGround(t, kLevel);
}

TEST(GroundPlugin, CameraPitchedTenDegreesDown) {
    TestCloud t(kTilted);
    makeGround("{camera_height_mm: 1500, inclination_deg: 10}").apply(t.cloud);
    expectGround(t, kTilted);
}

TEST(GroundPlugin, DefaultsAreALevelCameraAt1500Mm) {
    TestCloud t(kLevel);
    makeGround("{}").apply(t.cloud);
    expectGround(t, kLevel);
}

TEST(GroundPlugin, RefusesACloudAlreadyInTheGroundFrame) {
    TestCloud t(kLevel);
    CloudTransform ground = makeGround("{}");
    ground.apply(t.cloud);
    const std::vector<float> once = t.xyz;
    const std::string e = errorOf([&] { ground.apply(t.cloud); });
    EXPECT_NE(e.find("already in the ground frame"), std::string::npos) << e;
    EXPECT_EQ(t.xyz, once); // untouched
}

TEST(GroundPlugin, RefusesSettingsOutOfRange) {
    const PluginRecord &record = builtPlugins().require("ground", BINOCLE_KIND_CLOUD_TRANSFORM);
    expectRefused<CloudTransform>(record, "inclination_deg", "95", "90", "inclination_deg = 95: expected a decimal number >= -90 <= 90");
    expectRefused<CloudTransform>(record, "camera_height_mm", "-10", "0",
                                  "camera_height_mm = -10: expected a decimal number >= 0");
}

} // namespace
} // namespace binocle::test
