// SPDX-License-Identifier: MIT
// Tests of the built binocle_v4l2.so through the plugin host, on this machine's real
// devices: with none, every failure must be clear; and the example rig must load.
#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "host/plugin_host.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;

const binocle::PluginHost &host() {
    static binocle::PluginHost h;
    static const bool scanned = (h.scan(), true);
    (void)scanned;
    return h;
}

bool anyVideoNode() {
    std::error_code ec;
    for (fs::directory_iterator it("/dev", ec), end; !ec && it != end; it.increment(ec))
        if (it->path().filename().string().rfind("video", 0) == 0) return true;
    return false;
}

TEST(V4l2Module, IsFoundByTheHost) {
    const binocle::PluginRecord &record = host().require("v4l2", BINOCLE_KIND_STEREO_SOURCE);
    EXPECT_EQ(record.name, "v4l2");
    EXPECT_NE(record.path.find("binocle_v4l2.so"), std::string::npos);
}

TEST(V4l2Module, AMissingDeviceGivesAClearError) {
    if (fs::exists("/dev/video0")) GTEST_SKIP() << "this machine has a /dev/video0";
    const binocle::PluginRecord &record = host().require("v4l2", BINOCLE_KIND_STEREO_SOURCE);
    try {
        binocle::Source src(record, binocle::paramsFromYaml(record, "device_left: /dev/video0"));
        FAIL() << "opened a /dev/video0 that does not exist";
    } catch (const binocle::PluginError &e) {
        EXPECT_EQ(e.code(), BINOCLE_ERR_NOT_FOUND) << e.what();
        EXPECT_NE(std::string(e.what()).find("/dev/video0: no such device"), std::string::npos) << e.what();
    }
}

TEST(V4l2Module, EnumeratesNoDeviceWhereThereIsNone) {
    const binocle::PluginRecord &record = host().require("v4l2", BINOCLE_KIND_STEREO_SOURCE);
    const YAML::Node list = YAML::Load(binocle::Source::enumerateDevices(record));
    ASSERT_TRUE(list.IsSequence());
    if (!anyVideoNode()) EXPECT_EQ(list.size(), 0u);
    for (const auto &d : list) {
        EXPECT_TRUE(d["id"]);
        EXPECT_TRUE(d["description"]);
    }
}

TEST(V4l2Module, TheExampleRigIsValid) {
    const std::string file = std::string(BINOCLE_SOURCE_DIR) + "/configs/rigs/v4l2-uvc-side-by-side.yaml";
    const binocle::RigConfig rig = binocle::loadRig(file, {}, host());
    EXPECT_EQ(rig.source().plugin, "v4l2");
    EXPECT_EQ(rig.matcher().plugin, "sgbm");
    ASSERT_EQ(rig.transforms().size(), 1u);
    EXPECT_EQ(rig.transforms()[0].plugin, "ground");
    const binocle_param *layout = rig.source().params.find("layout");
    ASSERT_TRUE(layout);
    EXPECT_STREQ(layout->s, "side_by_side");
}

} // namespace
