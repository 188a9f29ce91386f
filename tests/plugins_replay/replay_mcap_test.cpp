// SPDX-License-Identifier: MIT
// The replay source's `mcap` layout, loaded through the plugin host: bags written here with
// Binocle::mcap (every image encoding, stamps, camera_info, faults) and bags written by
// the MCAP project's reference writer (tests/mcap/node), read back pixel-exact; and
// `binocle run` on a reference bag at a known constant disparity.
#include "../mcap/reference_scene.hpp"

#include "config/rig_config.hpp"
#include "core/calibration.hpp"
#include "core/error.hpp"
#include "core/image_io.hpp"
#include "host/plugin_host.hpp"

#include <binocle/mcap.hpp>
#include <binocle/ros2_messages.hpp>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace binocle;

namespace {

const PluginRecord &replayRecord() {
    static PluginHost host(std::vector<std::string>{BINOCLE_BUILD_PLUGIN_DIR});
    static const PluginRecord &record = []() -> const PluginRecord & {
        host.scan();
        return host.require("replay", BINOCLE_KIND_STEREO_SOURCE);
    }();
    return record;
}

cv::Mat noise(cv::Size size, int type, int seed) {
    cv::Mat m(size, type);
    cv::RNG rng(static_cast<uint64_t>(seed) + 1);
    rng.fill(m, cv::RNG::UNIFORM, 0, 256);
    return m;
}

bool equal(const cv::Mat &a, const cv::Mat &b) {
    return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// Writes a stereo bag: `frames` pairs of `encoding` images (the pixels of `pixels(side, i)`,
// as stored in the message), camera_info per side, stamps 100 ms apart (right +1 ms).
struct BagWriter {
    mcap::Writer w;
    uint16_t image, info, compressed;
    explicit BagWriter(const fs::path &file, mcap::Compression c = mcap::Compression::Zstd)
        : w(file.string(), [c] {
              mcap::WriterOptions o;
              o.compression = c;
              o.chunk_bytes = 8000;
              return o;
          }()) {
        image = w.addSchema(ros2::Image::kType, "ros2msg", ros2::definition(ros2::Image::kType));
        info = w.addSchema(ros2::CameraInfo::kType, "ros2msg", ros2::definition(ros2::CameraInfo::kType));
        compressed = w.addSchema(ros2::CompressedImage::kType, "ros2msg", ros2::definition(ros2::CompressedImage::kType));
    }
    void put(const std::string &topic, uint16_t schema, int64_t t, const std::vector<uint8_t> &bytes,
             const std::string &encoding = "cdr") {
        const uint16_t ch = w.addChannel(schema, topic, encoding);
        w.write(ch, 0, static_cast<uint64_t>(t), static_cast<uint64_t>(t), bytes.data(), bytes.size());
    }
    void putImage(const std::string &topic, int64_t stamp, const cv::Mat &px, const std::string &encoding) {
        ros2::Image m;
        m.header.stamp = ros2::Time::fromNs(stamp);
        m.header.frame_id = "cam";
        m.width = px.cols;
        m.height = px.rows;
        m.encoding = encoding;
        m.step = static_cast<uint32_t>(px.step[0]);
        m.data = px.data;
        m.size = px.total() * px.elemSize();
        put(topic, image, stamp, ros2::encode(m));
    }
    void putInfo(const std::string &topic, int64_t stamp, cv::Size size, double f, double txM) {
        ros2::CameraInfo ci;
        ci.header.stamp = ros2::Time::fromNs(stamp);
        ci.width = size.width;
        ci.height = size.height;
        ci.d = {0, 0, 0, 0, 0};
        ci.k = {f, 0, size.width / 2.0, 0, f, size.height / 2.0, 0, 0, 1};
        ci.r = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        ci.p = {f, 0, size.width / 2.0, -f * txM, 0, f, size.height / 2.0, 0, 0, 0, 1, 0};
        put(topic, info, stamp, ros2::encode(ci));
    }
};

constexpr int64_t kT0 = 1700000000000000000LL;

class ReplayMcap : public ::testing::Test {
protected:
    void SetUp() override {
        const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("binocle_replay_mcap_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        if (!HasFailure()) fs::remove_all(dir_, ec);
    }
    std::unique_ptr<Source> open(const std::string &yaml) {
        auto src = std::make_unique<Source>(replayRecord(), paramsFromYaml(replayRecord(), yaml));
        src->start();
        return src;
    }
    std::string openError(const std::string &yaml) {
        try {
            auto src = open(yaml);
            while (src->grab()) {
            }
        } catch (const Error &e) {
            return e.what();
        }
        ADD_FAILURE() << "no error: " << yaml;
        return {};
    }
    fs::path dir_;
};

} // namespace

TEST_F(ReplayMcap, EveryImageEncodingPairedByStampWithCameraInfoAsCalibration) {
    const fs::path bag = dir_ / "enc.mcap";
    const cv::Size size(24, 16);
    const std::vector<std::string> encodings{"mono8", "bgr8", "rgb8", "mono16", "bayer_rggb8"};
    {
        BagWriter b(bag);
        for (size_t i = 0; i < encodings.size(); ++i) {
            const int64_t t = kT0 + static_cast<int64_t>(i) * 100000000;
            const std::string &e = encodings[i];
            const int type = e == "bgr8" || e == "rgb8" ? CV_8UC3 : e == "mono16" ? CV_16UC1 : CV_8UC1;
            b.putImage("/rig/left/image_raw", t, noise(size, type, static_cast<int>(i)), e);
            b.putImage("/rig/right/image_raw", t + 1000000, noise(size, type, 100 + static_cast<int>(i)), e);
            b.putInfo("/rig/left/camera_info", t, size, 50, 0);
            b.putInfo("/rig/right/camera_info", t, size, 50, 0.12);
        }
        b.w.close();
    }
    auto src = open("{layout: mcap, bag: " + bag.string() + "}");
    for (size_t i = 0; i < encodings.size(); ++i) {
        SCOPED_TRACE(encodings[i]);
        auto f = src->grab();
        ASSERT_TRUE(f);
        EXPECT_EQ(f->raw().timestamp_left_ns, kT0 + static_cast<int64_t>(i) * 100000000);
        EXPECT_EQ(f->raw().timestamp_right_ns, f->raw().timestamp_left_ns + 1000000);
        const std::string &e = encodings[i];
        for (int side = 0; side < 2; ++side) {
            const cv::Mat stored = noise(size, e == "bgr8" || e == "rgb8" ? CV_8UC3 : e == "mono16" ? CV_16UC1 : CV_8UC1,
                                         static_cast<int>(i) + 100 * side);
            cv::Mat expected;
            if (e == "mono8") cv::cvtColor(stored, expected, cv::COLOR_GRAY2BGR);
            else if (e == "bgr8") expected = stored;
            else if (e == "rgb8") cv::cvtColor(stored, expected, cv::COLOR_RGB2BGR);
            else if (e == "mono16") {
                stored.convertTo(expected, CV_8U, 1.0 / 256);
                cv::cvtColor(expected, expected, cv::COLOR_GRAY2BGR);
            } else cv::cvtColor(stored, expected, cv::COLOR_BayerBG2BGR); // ROS rggb = OpenCV BG
            EXPECT_TRUE(equal(side ? f->right() : f->left(), expected)) << "side " << side;
        }
        EXPECT_EQ(YAML::Load(f->metadata())["left_topic"].as<std::string>(), "/rig/left/image_raw");
    }
    EXPECT_EQ(src->grab(), nullptr);
    const StereoCalibration cal = StereoCalibration::fromYaml(src->calibration(), "bag");
    EXPECT_EQ(cal.image_size, size);
    EXPECT_DOUBLE_EQ(cal.M1.at<double>(0, 0), 50);
    EXPECT_NEAR(cal.baselineMm(), 120, 1e-9);
    EXPECT_NEAR(cal.T.at<double>(0), -120, 1e-9);
    EXPECT_TRUE(cal.rectified);
    const YAML::Node stats = YAML::Load(src->statistics());
    EXPECT_EQ(stats["layout"].as<std::string>(), "mcap");
    EXPECT_EQ(stats["unpaired_left"].as<int>(), 0);
}

TEST_F(ReplayMcap, UnpairedImagesAreCountedAndSeekByTime) {
    const fs::path bag = dir_ / "pairs.mcap";
    const cv::Size size(8, 6);
    {
        BagWriter b(bag, mcap::Compression::Lz4);
        for (int i = 0; i < 20; ++i) {
            const int64_t t = kT0 + i * 100000000LL;
            if (i != 4) b.putImage("/a/left/image_raw", t, noise(size, CV_8UC1, i), "mono8");
            if (i != 7 && i != 8) b.putImage("/a/right/image_raw", t + (i == 10 ? 20000000 : 0), noise(size, CV_8UC1, 50 + i), "mono8");
        }
        b.w.close();
    }
    auto src = open("{bag: " + bag.string() + ", color: gray}"); // layout detected from `bag`
    int n = 0;
    while (auto f = src->grab()) {
        EXPECT_NE(f->raw().timestamp_left_ns, kT0 + 10 * 100000000LL); // 20 ms apart: not a pair
        ++n;
    }
    EXPECT_EQ(n, 16); // 20 - left 4 - right 7, 8 - the pair of 10
    const YAML::Node stats = YAML::Load(src->statistics());
    EXPECT_EQ(stats["unpaired_left"].as<int>(), 3);  // 7, 8, 10
    EXPECT_EQ(stats["unpaired_right"].as<int>(), 2); // 4, 10
    // A tolerance of 25 ms pairs frame 10 again.
    auto wide = open("{bag: " + bag.string() + ", pair_tolerance_ms: 25}");
    n = 0;
    while (wide->grab()) ++n;
    EXPECT_EQ(n, 17);
    // start_s 1.0, duration_s 0.45: frames 10 .. 14 by log time.
    auto window = open("{bag: " + bag.string() + ", start_s: 1.0, duration_s: 0.45, pair_tolerance_ms: 25, color: gray}");
    auto first = window->grab();
    ASSERT_TRUE(first);
    EXPECT_EQ(first->raw().timestamp_left_ns, kT0 + 10 * 100000000LL);
    EXPECT_TRUE(equal(first->left(), noise(size, CV_8UC1, 10)));
    n = 1;
    while (window->grab()) ++n;
    EXPECT_EQ(n, 5);
}

TEST_F(ReplayMcap, Rosbag2FolderWithMetadataYaml) {
    fs::create_directories(dir_ / "run1");
    {
        BagWriter b(dir_ / "run1" / "run1_0.mcap");
        b.putImage("/s/left/image_rect", kT0, noise({8, 6}, CV_8UC1, 1), "mono8");
        b.putImage("/s/right/image_rect", kT0, noise({8, 6}, CV_8UC1, 2), "mono8");
        b.w.close();
    }
    std::ofstream(dir_ / "run1" / "metadata.yaml") << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n"
                                                      "  relative_file_paths:\n    - run1_0.mcap\n";
    auto src = open("{folder: " + (dir_ / "run1").string() + ", color: gray}");
    auto f = src->grab();
    ASSERT_TRUE(f);
    EXPECT_TRUE(equal(f->right(), noise({8, 6}, CV_8UC1, 2)));
    EXPECT_TRUE(src->calibration().empty()); // no camera_info: a warning, no calibration
    std::ofstream(dir_ / "run1" / "metadata.yaml", std::ios::trunc)
        << "rosbag2_bagfile_information:\n  storage_identifier: mcap\n  relative_file_paths:\n    - ../../etc/passwd\n";
    EXPECT_NE(openError("{folder: " + (dir_ / "run1").string() + "}").find("'..'"), std::string::npos);
}

TEST_F(ReplayMcap, BadBagsAreRefusedNamingFileTopicAndOffset) {
    const cv::Size size(8, 6);
    // A topic that is missing: the error lists the bag's topics.
    {
        BagWriter b(dir_ / "one.mcap");
        b.putImage("/only/left/image_raw", kT0, noise(size, CV_8UC1, 1), "mono8");
        b.w.close();
    }
    std::string e = openError("{bag: " + (dir_ / "one.mcap").string() + "}");
    EXPECT_NE(e.find("no pair of image topics"), std::string::npos) << e;
    EXPECT_NE(e.find("/only/left/image_raw (sensor_msgs/msg/Image, 1 messages)"), std::string::npos) << e;
    e = openError("{bag: " + (dir_ / "one.mcap").string() + ", left_topic: /only/left/image_raw, right_topic: /x/right}");
    EXPECT_NE(e.find("has no image topic '/x/right'"), std::string::npos) << e;
    // Step disagreeing with the data.
    {
        BagWriter b(dir_ / "step.mcap");
        ros2::Image m;
        m.width = 8;
        m.height = 6;
        m.encoding = "mono8";
        m.step = 9;
        std::vector<uint8_t> px(48);
        m.data = px.data();
        m.size = px.size();
        b.put("/c/left/image_raw", b.image, kT0, ros2::encode(m));
        b.put("/c/right/image_raw", b.image, kT0, ros2::encode(m));
        b.w.close();
    }
    e = openError("{bag: " + (dir_ / "step.mcap").string() + "}");
    EXPECT_NE(e.find("step.mcap: topic /c/left/image_raw, message at offset"), std::string::npos) << e;
    EXPECT_NE(e.find("data holds 48 bytes but step x height = 9 x 6 = 54"), std::string::npos) << e;
    // A message encoding that is not CDR.
    {
        BagWriter b(dir_ / "json.mcap");
        b.put("/j/left/image_raw", b.image, kT0, {1, 2}, "json");
        b.put("/j/right/image_raw", b.image, kT0, {1, 2}, "json");
        b.w.close();
    }
    e = openError("{bag: " + (dir_ / "json.mcap").string() + "}");
    EXPECT_NE(e.find("message encoding 'json'; expected cdr"), std::string::npos) << e;
    // A file that is not MCAP, and one cut inside its header.
    std::ofstream(dir_ / "not.mcap") << "hello, this is not a bag at all";
    e = openError("{bag: " + (dir_ / "not.mcap").string() + "}");
    EXPECT_NE(e.find("not.mcap does not start with the MCAP magic"), std::string::npos) << e;
}

TEST_F(ReplayMcap, CompressedImagesPngAndJpeg) {
    const cv::Size size(16, 12);
    const fs::path bag = dir_ / "c.mcap";
    const cv::Mat l = noise(size, CV_8UC3, 1), r = noise(size, CV_8UC3, 2);
    {
        BagWriter b(bag);
        for (int side = 0; side < 2; ++side) {
            std::vector<uint8_t> png;
            cv::imencode(".png", side ? r : l, png);
            ros2::CompressedImage m;
            m.header.stamp = ros2::Time::fromNs(kT0);
            m.format = "png";
            m.data = png.data();
            m.size = png.size();
            b.put(side ? "/z/right/image_raw/compressed" : "/z/left/image_raw/compressed", b.compressed, kT0, ros2::encode(m));
        }
        b.w.close();
    }
    auto src = open("{bag: " + bag.string() + "}");
    auto f = src->grab();
    ASSERT_TRUE(f);
    EXPECT_TRUE(equal(f->left(), l));
    EXPECT_TRUE(equal(f->right(), r));
}

// ---- Bags from the reference writer ----------------------------------------------------------

class ReplayReferenceBag : public ReplayMcap {
protected:
    void SetUp() override {
        ReplayMcap::SetUp();
        const std::string missing = test::referenceMissing();
        if (!missing.empty()) GTEST_SKIP() << missing;
    }
    fs::path referenceBag(const std::string &name, const std::string &args) {
        const fs::path file = dir_ / (name + ".mcap");
        int status = 0;
        test::runCommand("cd '" + test::nodeFolder() + "' && node write_reference.cjs '" + file.string() + "' " + args, status);
        EXPECT_EQ(status, 0) << args;
        return file;
    }
};

TEST_F(ReplayReferenceBag, ReplaysPixelExactWithItsCameraInfo) {
    for (const std::string args : {"--compression zstd", "--compression none --no-chunk-index"}) {
        SCOPED_TRACE(args);
        const fs::path bag = referenceBag(args.size() > 20 ? "none" : "zstd", args + " --frames 4 --width 64 --height 48 --disparity 8");
        auto src = open("{bag: " + bag.string() + ", color: gray}");
        for (int i = 0; i < 4; ++i) {
            auto f = src->grab();
            ASSERT_TRUE(f);
            const auto tex = test::referenceTexture(72, 48, i);
            int wrong = 0;
            for (int side = 0; side < 2; ++side) {
                const cv::Mat m = side ? f->right() : f->left();
                for (int y = 0; y < 48; ++y)
                    for (int x = 0; x < 64; ++x) wrong += m.at<uint8_t>(y, x) != test::referencePixel(tex, 64, 8, side, x, y);
            }
            EXPECT_EQ(wrong, 0) << "frame " << i;
        }
        const StereoCalibration cal = StereoCalibration::fromYaml(src->calibration(), "reference bag");
        EXPECT_NEAR(cal.baselineMm(), 120, 1e-9);
        EXPECT_DOUBLE_EQ(cal.focalLengthPx(), 100);
    }
}

// The scene: a reference bag at a constant disparity of 8 px through `binocle run`
// (sgbm), its CameraInfo as the calibration.
TEST_F(ReplayReferenceBag, BinocleRunFindsTheConstantDisparity) {
    const fs::path bag = referenceBag("scene", "--frames 2 --width 160 --height 120 --disparity 8");
    const fs::path rig = dir_ / "rig.yaml";
    std::ofstream(rig) << "name: bag\nsource:\n  plugin: replay\n  bag: " << bag.string()
                       << "\n  color: gray\nmatcher:\n  plugin: sgbm\n  num_disparities: 32\n  block_size: 5\n"
                          "outputs:\n  disparity_png: true\n";
    int status = 0;
    const std::string log = test::runCommand(std::string(BINOCLE_CLI) + " run '" + rig.string() + "' --out '" +
                                                 (dir_ / "out").string() + "' --quiet 2>&1",
                                             status);
    ASSERT_EQ(status, 0) << log;
    const cv::Mat d = readDisparityPng16((dir_ / "out" / "disparity_000000.png").string());
    ASSERT_EQ(d.size(), cv::Size(160, 120));
    // Inside the image (away from the left band that has no match and the borders).
    int right = 0, counted = 0;
    for (int y = 10; y < 110; ++y)
        for (int x = 48; x < 150; ++x) {
            ++counted;
            right += std::abs(d.at<float>(y, x) - 8.0f) < 0.5f;
        }
    EXPECT_GT(right, counted * 95 / 100) << right << " of " << counted << " pixels at 8 +- 0.5 px";
}
