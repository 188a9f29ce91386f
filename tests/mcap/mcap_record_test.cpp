// SPDX-License-Identifier: MIT
// `binocle record --format mcap` end to end: the simulated Videre head recorded to a
// rosbag2 bag that the reference reader (npm @mcap/core by its index, Foxglove's ROS 2
// deserialiser) decodes entirely; and the bag replayed through `binocle run` gives the
// same disparity as the live run.
#include "reference_scene.hpp"

#include "core/image_io.hpp"

#include <binocle/mcap.hpp>
#include <binocle/ros2_messages.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <filesystem>
#include <fstream>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace binocle;
using nlohmann::json;

namespace {

class McapRecord : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("binocle_mcap_record_" + std::to_string(::getpid()) + "_" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);
    }
    std::string cli(const std::string &args, int &status) {
        return test::runCommand("BINOCLE_PLUGIN_PATH='" + std::string(BINOCLE_BUILD_PLUGIN_DIR) + "' '" + BINOCLE_CLI +
                                    "' " + args + " 2>&1",
                                status);
    }
    fs::path dir_;
};

const std::string kRig = std::string(BINOCLE_SOURCE_DIR) + "/configs/rigs/sim-videre.yaml";

} // namespace

TEST_F(McapRecord, RecordedBagDecodesEntirelyWithTheReferenceReader) {
    int status = 0;
    const fs::path out = dir_ / "x";
    const std::string log = cli("record '" + kRig + "' --format mcap --frames 6 --out '" + out.string() +
                                    "' --quiet --ros-namespace /videre --frame-id-left cam_l",
                                status);
    ASSERT_EQ(status, 0) << log;
    const fs::path bag = out / "x_0.mcap";
    ASSERT_TRUE(fs::is_regular_file(bag)) << log;
    for (const char *f : {"metadata.yaml", "rig.yaml", "summary.json"}) EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
    std::ifstream meta(out / "metadata.yaml");
    const std::string metaText((std::istreambuf_iterator<char>(meta)), {});
    EXPECT_NE(metaText.find("storage_identifier: mcap"), std::string::npos);
    EXPECT_NE(metaText.find("message_count: 24"), std::string::npos) << metaText;
    EXPECT_NE(metaText.find("name: /videre/left/camera_info"), std::string::npos);

    // Our reader, by the index.
    mcap::Reader r(bag.string());
    EXPECT_TRUE(r.indexed());
    EXPECT_EQ(r.statistics().message_count, 24u);
    EXPECT_EQ(r.profile(), "ros2");

    const std::string missing = test::referenceMissing();
    if (!missing.empty()) GTEST_SKIP() << missing;
    const std::string text =
        test::runCommand("cd '" + test::nodeFolder() + "' && node read_reference.cjs '" + bag.string() + "'", status);
    ASSERT_EQ(status, 0);
    const json j = json::parse(text);
    EXPECT_EQ(j["header"]["profile"], "ros2");
    EXPECT_EQ(j["chunk_compressions"][0], "zstd");
    EXPECT_GE(j["chunks"].get<int>(), 1);
    std::map<std::string, std::vector<int64_t>> stamps;
    for (const json &m : j["messages"]) {
        const std::string topic = m["topic"];
        const json &v = m["value"];
        stamps[topic].push_back(int64_t{v["header"]["stamp"]["sec"].get<int32_t>()} * 1000000000 +
                                v["header"]["stamp"]["nanosec"].get<int64_t>());
        if (topic.find("image_raw") != std::string::npos) {
            EXPECT_EQ(v["encoding"], "mono8");
            EXPECT_EQ(v["width"], 320);
            EXPECT_EQ(v["height"], 240);
            EXPECT_EQ(v["step"], 320);
            EXPECT_EQ(v["data"]["length"], 320 * 240);
            EXPECT_EQ(v["header"]["frame_id"], topic.find("left") != std::string::npos ? "cam_l" : "binocle_right_optical");
        } else {
            EXPECT_EQ(v["distortion_model"], "plumb_bob");
            EXPECT_EQ(v["width"], 320);
            EXPECT_EQ(v["d"].size(), 5u);
            EXPECT_GT(v["k"][0].get<double>(), 0);
            if (topic.find("right") != std::string::npos) {
                // P(0,3) = -fx' B in metres: B = 150 mm.
                EXPECT_NEAR(-v["p"][3].get<double>() / v["p"][0].get<double>(), 0.150, 1e-6);
            }
        }
    }
    ASSERT_EQ(stamps.size(), 4u);
    for (const auto &[topic, s] : stamps) {
        EXPECT_EQ(s.size(), 6u) << topic;
        for (size_t i = 1; i < s.size(); ++i) EXPECT_GT(s[i], s[i - 1]) << topic;
    }
}

// Round trip: record --format mcap, then replay the bag (its CameraInfo as calibration):
// the same disparity as the live run, pixel for pixel.
TEST_F(McapRecord, ReplayedBagGivesTheLiveRunsDisparity) {
    int status = 0;
    std::string log = cli("record '" + kRig + "' --format mcap --frames 2 --out '" + (dir_ / "bag").string() + "' --quiet", status);
    ASSERT_EQ(status, 0) << log;
    log = cli("run '" + kRig + "' --frames 2 --out '" + (dir_ / "live").string() + "' --quiet", status);
    ASSERT_EQ(status, 0) << log;
    // The rig with the bag as its source.
    std::ifstream in(kRig);
    std::string rig((std::istreambuf_iterator<char>(in)), {});
    // The evaluators are left out: the paper evaluator needs the sim's panel metadata.
    const size_t a = rig.find("source:"), b = rig.find("matcher:"), e = rig.find("evaluators:"), o = rig.find("outputs:");
    rig = rig.substr(0, a) + "source:\n  plugin: replay\n  bag: " + (dir_ / "bag").string() + "\n  color: gray\n" +
          rig.substr(b, e - b) + rig.substr(o);
    // Paths in the rig (the paper evaluator's scene) are relative to configs/rigs.
    const fs::path rigFile = fs::path(BINOCLE_SOURCE_DIR) / "configs" / "rigs" / (".mcap_test_" + std::to_string(::getpid()) + ".yaml");
    std::ofstream(rigFile) << rig;
    log = cli("run '" + rigFile.string() + "' --out '" + (dir_ / "replayed").string() + "' --quiet", status);
    fs::remove(rigFile);
    ASSERT_EQ(status, 0) << log;
    for (const char *f : {"disparity_000000.png", "disparity_000001.png"}) {
        const cv::Mat live = readDisparityPng16((dir_ / "live" / f).string());
        const cv::Mat replayed = readDisparityPng16((dir_ / "replayed" / f).string());
        ASSERT_EQ(live.size(), replayed.size()) << f;
        EXPECT_EQ(cv::norm(live, replayed, cv::NORM_INF), 0) << f;
    }
}

// `binocle run --mcap`: rectified images, DisparityImage, PointCloud2 (ground frame) and
// the figures, decoded by the reference reader with consistent sizes.
TEST_F(McapRecord, RunWritesDisparityCloudAndFigures) {
    int status = 0;
    const std::string log = cli("run '" + kRig + "' --frames 2 --out '" + (dir_ / "run").string() + "' --quiet --mcap", status);
    ASSERT_EQ(status, 0) << log;
    const fs::path bag = dir_ / "run" / "bag" / "bag_0.mcap";
    ASSERT_TRUE(fs::is_regular_file(bag)) << log;
    EXPECT_TRUE(fs::is_regular_file(dir_ / "run" / "bag" / "metadata.yaml"));
    const std::string missing = test::referenceMissing();
    if (!missing.empty()) GTEST_SKIP() << missing;
    const std::string text =
        test::runCommand("cd '" + test::nodeFolder() + "' && node read_reference.cjs '" + bag.string() + "'", status);
    ASSERT_EQ(status, 0);
    const json j = json::parse(text);
    std::map<std::string, int> count;
    for (const json &m : j["messages"]) {
        const std::string topic = m["topic"];
        const json &v = m["value"];
        ++count[topic];
        if (topic == "/binocle/disparity") {
            const json &im = v["image"];
            EXPECT_EQ(im["encoding"], "32FC1");
            EXPECT_EQ(im["width"], 320);
            EXPECT_EQ(im["step"], 320 * 4);
            EXPECT_EQ(im["data"]["length"], 320 * 4 * 240);
            EXPECT_GT(v["f"].get<double>(), 0);
            EXPECT_NEAR(v["t"].get<double>(), 0.150, 1e-6);
            EXPECT_GT(v["max_disparity"].get<double>(), 1);
        } else if (topic == "/binocle/points") {
            EXPECT_EQ(v["header"]["frame_id"], "binocle_ground");
            EXPECT_EQ(v["point_step"], 12);
            EXPECT_GT(v["width"].get<int>(), 1000);
            EXPECT_EQ(v["row_step"].get<int>(), 12 * v["width"].get<int>());
            EXPECT_EQ(v["data"]["length"].get<int>(), v["row_step"].get<int>() * v["height"].get<int>());
        } else if (topic == "/binocle/figures") {
            EXPECT_GE(v["status"].size(), 1u);
        } else if (topic.find("image_rect") != std::string::npos) {
            EXPECT_EQ(v["width"], 320);
        } else {
            ADD_FAILURE() << topic;
        }
    }
    for (const char *t : {"/binocle/disparity", "/binocle/points", "/binocle/figures", "/binocle/left/image_rect",
                          "/binocle/right/image_rect"})
        EXPECT_EQ(count[t], 2) << t;
}

TEST_F(McapRecord, BadNamespaceIsRefusedBeforeAnythingIsWritten) {
    int status = 0;
    const std::string log =
        cli("record '" + kRig + "' --format mcap --frames 1 --out '" + (dir_ / "y").string() + "' --ros-namespace 'a b'", status);
    EXPECT_NE(status, 0);
    EXPECT_NE(log.find("--ros-namespace: 'a b': it does not start with '/'; ROS 2 expects"), std::string::npos) << log;
    EXPECT_FALSE(fs::exists(dir_ / "y"));
}

// A full disk (a tmpfs in a private mount namespace; root only): the recording stops with
// an error, and the pairs it claims (its last line and summary.json's pairs_written) are
// the pairs a reader recovers: the reference stream reader (@mcap/core, front to back, as
// a bag without its summary is read) and Binocle's replay. It used to claim the pairs of
// the chunk that never reached the disk (16 claimed, 0 replayed; 48 claimed, 32 replayed).
TEST_F(McapRecord, OnAFullDiskTheClaimIsWhatAReaderRecovers) {
    int status = 0;
    test::runCommand("unshare -m true 2>&1", status);
    if (status != 0) GTEST_SKIP() << "cannot make a mount namespace here (needs root)";
    const std::string missing = test::referenceMissing();
    for (const char *size : {"1m", "3m", "12m"}) {
        SCOPED_TRACE(std::string("a disk of ") + size);
        const fs::path disk = dir_ / (std::string("disk") + size), copy = dir_ / (std::string("copy") + size);
        fs::create_directories(disk);
        fs::create_directories(copy);
        const std::string bag = (disk / "bag").string();
        const std::string log = test::runCommand(
            "BINOCLE_PLUGIN_PATH='" + std::string(BINOCLE_BUILD_PLUGIN_DIR) + "' unshare -m sh -c \"mount -t tmpfs -o size=" +
                size + " tmpfs '" + disk.string() + "' || exit 99; timeout -s KILL 120 '" + BINOCLE_CLI + "' record '" + kRig +
                "' --format mcap --out '" + bag + "' --quiet; echo exit=\\$?; cp -a '" + bag + "' '" + copy.string() + "'\" 2>&1",
            status);
        if (WEXITSTATUS(status) == 99) GTEST_SKIP() << "cannot mount a tmpfs here: " << log;
        ASSERT_NE(log.find("exit=1"), std::string::npos) << log;
        EXPECT_NE(log.find("No space left on device"), std::string::npos) << log;
        const fs::path kept = copy / "bag";
        std::ifstream in(kept / "summary.json");
        ASSERT_TRUE(in) << "no summary.json: " << log;
        const int64_t claimed = json::parse(in)["pairs_written"].get<int64_t>();
        EXPECT_NE(log.find("the " + std::to_string(claimed) + " frame(s) already written are complete"), std::string::npos)
            << log;
        // Binocle's replay: the bag recorded again into a folder, on a disk with room.
        const std::string rig = (dir_ / (std::string("replay") + size + ".yaml")).string();
        std::ofstream(rig) << "name: replay-full-disk\nsource: {plugin: replay, bag: " << kept.string()
                           << ", color: gray}\nmatcher: {plugin: sgbm}\n";
        const std::string again = cli("record '" + rig + "' --out '" + (dir_ / (std::string("again") + size)).string() + "' --quiet", status);
        int64_t replayed = 0;
        if (claimed > 0) {
            ASSERT_EQ(status, 0) << again;
            std::ifstream s(dir_ / (std::string("again") + size) / "summary.json");
            replayed = json::parse(s)["pairs_written"].get<int64_t>();
        }
        EXPECT_EQ(replayed, claimed) << log << again;
        std::cout << "[ figures  ] mcap record on a " << size << " disk: " << claimed << " pair(s) claimed, " << replayed
                  << " replayed\n";
        if (!missing.empty()) continue;
        const fs::path file = kept / "bag_0.mcap";
        const json j = json::parse(test::runCommand("cd '" + test::nodeFolder() + "' && node read_stream.cjs '" + file.string() + "'", status));
        ASSERT_EQ(status, 0);
        EXPECT_FALSE(j["complete"].get<bool>()); // no room was left for the summary
        for (const char *topic : {"/binocle/left/image_raw", "/binocle/right/image_raw", "/binocle/left/camera_info",
                                  "/binocle/right/camera_info"})
            EXPECT_EQ(j["by_topic"].value(topic, 0), claimed) << topic << ": " << j.dump();
    }
    if (!missing.empty()) GTEST_SKIP() << missing;
}
