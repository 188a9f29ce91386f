// SPDX-License-Identifier: MIT
// Tests of the built binocle_videre1394.so through the plugin host, on this machine's
// real IEEE-1394 stack: with no bus or no camera, every failure must be clear; and the
// example rig of the paper's head must load.
#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "host/plugin_host.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <string>

namespace {

const binocle::PluginHost &host() {
    static binocle::PluginHost h;
    static const bool scanned = (h.scan(), true);
    (void)scanned;
    return h;
}

const binocle::PluginRecord &videre() { return host().require("videre1394", BINOCLE_KIND_STEREO_SOURCE); }

TEST(VidereModule, IsFoundByTheHost) {
    EXPECT_EQ(videre().name, "videre1394");
    EXPECT_NE(videre().path.find("binocle_videre1394.so"), std::string::npos);
}

TEST(VidereModule, NoBusOrNoCameraGivesAClearError) {
    const YAML::Node cameras = YAML::Load(binocle::Source::enumerateDevices(videre()));
    ASSERT_TRUE(cameras.IsSequence());
    if (cameras.size() > 0) GTEST_SKIP() << "this machine has IEEE-1394 cameras";
    try {
        binocle::Source src(videre(), binocle::paramsFromYaml(videre(), "{}"));
        FAIL() << "opened a head on a machine without one";
    } catch (const binocle::PluginError &e) {
        const std::string m = e.what();
        EXPECT_EQ(e.code(), BINOCLE_ERR_NOT_FOUND) << m;
        const bool noCamera = m.find("videre1394: no IEEE-1394 camera found (bus: ") != std::string::npos;
        const bool noBus = m.find("videre1394: no IEEE-1394 bus found (dc1394_new failed)") != std::string::npos;
        EXPECT_TRUE(noCamera || noBus) << m;
    }
}

TEST(VidereModule, ThePapersHeadRigIsValid) {
    const std::string file = std::string(BINOCLE_SOURCE_DIR) + "/configs/rigs/videre-sth-mdcs2.yaml";
    const binocle::RigConfig rig = binocle::loadRig(file, {}, host());
    EXPECT_EQ(rig.source().plugin, "videre1394");
    const binocle_param *decimation = rig.source().params.find("decimation");
    ASSERT_TRUE(decimation);
    EXPECT_EQ(decimation->i, 4);
    EXPECT_EQ(rig.matcher().plugin, "sgbm");
    ASSERT_EQ(rig.transforms().size(), 1u);
    EXPECT_EQ(rig.transforms()[0].plugin, "ground");
    const binocle_param *height = rig.transforms()[0].params.find("camera_height_mm");
    ASSERT_TRUE(height);
    EXPECT_EQ(height->d, 1500);
    const binocle_param *inclination = rig.transforms()[0].params.find("inclination_deg");
    ASSERT_TRUE(inclination);
    EXPECT_EQ(inclination->d, 0);
    EXPECT_TRUE(rig.evaluators().empty());
}

} // namespace
