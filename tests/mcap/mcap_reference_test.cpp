// SPDX-License-Identifier: MIT
// Binocle::mcap against the MCAP project's reference implementation (npm, see
// scripts/install-npm-test-deps.sh): its indexed reader and the Foxglove ROS 2 deserialiser
// decode every message of every type Binocle writes, under each compression; and bags
// written by its writer (zstd, uncompressed, without chunk index, without chunks) read back
// pixel-exact.
#include "reference_scene.hpp"

#include <binocle/mcap.hpp>
#include <binocle/ros2_messages.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace binocle;
using nlohmann::json;

namespace {

fs::path tempDir(const std::string &name) {
    fs::path d = fs::temp_directory_path() / ("binocle_mcapref_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string quoted(const std::string &s) { return "'" + s + "'"; }

// What the reference reader makes of `file` (by its index).
json referenceRead(const fs::path &file) {
    int status = 0;
    const std::string out = test::runCommand(
        "cd " + quoted(test::nodeFolder()) + " && node read_reference.cjs " + quoted(file.string()), status);
    EXPECT_EQ(status, 0) << "read_reference.cjs failed on " << file;
    return status == 0 ? json::parse(out) : json();
}

std::vector<uint8_t> bytesOf(const std::vector<float> &v) {
    std::vector<uint8_t> b(v.size() * 4);
    std::memcpy(b.data(), v.data(), b.size());
    return b;
}

// The reference script digests byte arrays with CRC-32.
uint32_t digest(const std::vector<uint8_t> &b) { return mcap::crc32(b.data(), b.size()); }

class McapReference : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string missing = test::referenceMissing();
        if (!missing.empty()) GTEST_SKIP() << missing;
    }
};

} // namespace

// Every message type Binocle writes, as `binocle record` and `binocle run` write them.
TEST_F(McapReference, ReadsEveryTypeBinocleWrites) {
    const fs::path dir = tempDir("types");
    for (auto c : {mcap::Compression::Zstd, mcap::Compression::Lz4, mcap::Compression::None}) {
        SCOPED_TRACE(mcap::compressionName(c));
        const fs::path file = dir / (std::string("all_") + mcap::compressionName(c) + ".mcap");
        mcap::WriterOptions o;
        o.compression = c;
        o.chunk_bytes = 20000;
        mcap::Writer w(file.string(), o);
        auto channel = [&](const char *type, const std::string &topic) {
            return w.addChannel(w.addSchema(type, "ros2msg", ros2::definition(type)), topic, "cdr");
        };
        const uint16_t img = channel(ros2::Image::kType, "/binocle/left/image_raw");
        const uint16_t img16 = channel(ros2::Image::kType, "/binocle/right/image_raw");
        const uint16_t info = channel(ros2::CameraInfo::kType, "/binocle/left/camera_info");
        const uint16_t disp = channel(ros2::DisparityImage::kType, "/binocle/disparity");
        const uint16_t cloud = channel(ros2::PointCloud2::kType, "/binocle/points");
        const uint16_t diag = channel(ros2::DiagnosticArray::kType, "/binocle/figures");
        const uint16_t comp = channel(ros2::CompressedImage::kType, "/binocle/left/image_raw/compressed");
        const int frames = 4;
        std::vector<uint32_t> pixelDigests, disparityDigests, cloudDigests;
        for (int i = 0; i < frames; ++i) {
            const int64_t t = 1700000000000000000LL + i * 100000000LL;
            const auto stamp = ros2::Time::fromNs(t);
            auto put = [&](uint16_t ch, const std::vector<uint8_t> &b) {
                w.write(ch, static_cast<uint32_t>(i), static_cast<uint64_t>(t), static_cast<uint64_t>(t), b.data(), b.size());
            };
            std::vector<uint8_t> px(40 * 30 * 3);
            for (size_t k = 0; k < px.size(); ++k) px[k] = static_cast<uint8_t>(k * 31 + i);
            ros2::Image m;
            m.header = {stamp, "left_optical"};
            m.width = 40;
            m.height = 30;
            m.encoding = "bgr8";
            m.step = 120;
            m.data = px.data();
            m.size = px.size();
            put(img, ros2::encode(m));
            pixelDigests.push_back(digest(px));
            std::vector<uint8_t> px16(40 * 30 * 2, static_cast<uint8_t>(i));
            m.encoding = "mono16";
            m.step = 80;
            m.data = px16.data();
            m.size = px16.size();
            put(img16, ros2::encode(m));
            ros2::CameraInfo ci;
            ci.header = {stamp, "left_optical"};
            ci.width = 40;
            ci.height = 30;
            ci.d = {0.1, 0.01, 0.001, 0.0001, 0.5};
            ci.k = {50, 0, 20, 0, 51, 15, 0, 0, 1};
            ci.r = {1, 0, 0, 0, 1, 0, 0, 0, 1};
            ci.p = {50, 0, 20, -6, 0, 50, 15, 0, 0, 0, 1, 0};
            put(info, ros2::encode(ci));
            std::vector<float> d(40 * 30);
            for (size_t k = 0; k < d.size(); ++k) d[k] = static_cast<float>(k % 40) * 0.25f + i;
            const auto db = bytesOf(d);
            ros2::DisparityImage di;
            di.header = {stamp, "left_optical"};
            di.image.header = di.header;
            di.image.width = 40;
            di.image.height = 30;
            di.image.encoding = "32FC1";
            di.image.step = 160;
            di.image.data = db.data();
            di.image.size = db.size();
            di.f = 50;
            di.t = 0.12f;
            di.min_disparity = 0;
            di.max_disparity = 16;
            di.delta_d = 1.0f / 16;
            di.valid_window = {2, 3, 20, 30, false};
            put(disp, ros2::encode(di));
            disparityDigests.push_back(digest(db));
            std::vector<float> xyz;
            for (int k = 0; k < 25; ++k) xyz.insert(xyz.end(), {k * 0.1f, -k * 0.2f, 1.5f + i});
            const auto pb = bytesOf(xyz);
            ros2::PointCloud2 pc;
            pc.header = {stamp, "ground"};
            pc.width = 25;
            pc.fields = {{"x", 0, ros2::PointField::FLOAT32, 1}, {"y", 4, ros2::PointField::FLOAT32, 1},
                         {"z", 8, ros2::PointField::FLOAT32, 1}};
            pc.point_step = 12;
            pc.row_step = 300;
            pc.data = pb.data();
            pc.size = pb.size();
            pc.is_dense = true;
            put(cloud, ros2::encode(pc));
            cloudDigests.push_back(digest(pb));
            ros2::DiagnosticArray da;
            da.header = {stamp, "rig"};
            da.status.push_back({ros2::DiagnosticStatus::OK, "binocle/evaluator", "figures of frame " + std::to_string(i),
                                 "rig", {{"planar_efficiency", "0.5"}, {"frame", std::to_string(i)}}});
            put(diag, ros2::encode(da));
            ros2::CompressedImage ci2;
            ci2.header = {stamp, "left_optical"};
            ci2.format = "png";
            ci2.data = px.data();
            ci2.size = 17;
            put(comp, ros2::encode(ci2));
        }
        w.close();

        const json r = referenceRead(file);
        ASSERT_FALSE(r.is_null());
        EXPECT_EQ(r["header"]["profile"], "ros2");
        EXPECT_EQ(r["statistics"]["message_count"], std::to_string(frames * 7));
        EXPECT_GE(r["chunks"].get<int>(), 2);
        EXPECT_EQ(r["chunks"], r["statistics"]["chunk_count"]);
        EXPECT_EQ(r["chunk_compressions"][0], mcap::compressionName(c));
        EXPECT_NE(r["data_section_crc"], 0);
        ASSERT_EQ(r["channels"].size(), 7u);
        for (const json &ch : r["channels"]) {
            EXPECT_EQ(ch["message_encoding"], "cdr");
            EXPECT_EQ(ch["schema_encoding"], "ros2msg");
        }
        std::map<std::string, int> seen;
        uint64_t lastTime = 0;
        for (const json &m : r["messages"]) {
            const std::string topic = m["topic"];
            const int i = seen[topic]++;
            const json &v = m["value"];
            const uint64_t t = std::stoull(m["log_time"].get<std::string>());
            EXPECT_GE(t, lastTime);
            lastTime = t;
            EXPECT_EQ(v["header"]["stamp"]["sec"], 1700000000);
            EXPECT_EQ(v["header"]["stamp"]["nanosec"], i * 100000000);
            if (topic == "/binocle/left/image_raw") {
                EXPECT_EQ(v["encoding"], "bgr8");
                EXPECT_EQ(v["width"], 40);
                EXPECT_EQ(v["step"], 120);
                EXPECT_EQ(v["data"]["crc32"], pixelDigests[i]);
            } else if (topic == "/binocle/right/image_raw") {
                EXPECT_EQ(v["encoding"], "mono16");
                EXPECT_EQ(v["data"]["length"], 2400);
            } else if (topic == "/binocle/left/camera_info") {
                EXPECT_EQ(v["distortion_model"], "plumb_bob");
                EXPECT_EQ(v["d"], json({0.1, 0.01, 0.001, 0.0001, 0.5}));
                EXPECT_EQ(v["k"], json({50, 0, 20, 0, 51, 15, 0, 0, 1}));
                EXPECT_EQ(v["p"][3], -6);
                EXPECT_EQ(v["roi"]["do_rectify"], false);
            } else if (topic == "/binocle/disparity") {
                EXPECT_EQ(v["image"]["encoding"], "32FC1");
                EXPECT_EQ(v["image"]["data"]["crc32"], disparityDigests[i]);
                EXPECT_FLOAT_EQ(v["f"].get<float>(), 50.0f);
                EXPECT_FLOAT_EQ(v["t"].get<float>(), 0.12f);
                EXPECT_FLOAT_EQ(v["delta_d"].get<float>(), 0.0625f);
                EXPECT_EQ(v["valid_window"]["y_offset"], 3);
                EXPECT_EQ(v["max_disparity"], 16);
            } else if (topic == "/binocle/points") {
                EXPECT_EQ(v["fields"].size(), 3u);
                EXPECT_EQ(v["fields"][2]["name"], "z");
                EXPECT_EQ(v["fields"][2]["datatype"], 7);
                EXPECT_EQ(v["point_step"], 12);
                EXPECT_EQ(v["data"]["length"], v["row_step"].get<int>() * v["height"].get<int>());
                EXPECT_EQ(v["data"]["crc32"], cloudDigests[i]);
                EXPECT_EQ(v["is_dense"], true);
            } else if (topic == "/binocle/figures") {
                EXPECT_EQ(v["status"][0]["name"], "binocle/evaluator");
                EXPECT_EQ(v["status"][0]["values"][1]["value"], std::to_string(i));
            } else if (topic == "/binocle/left/image_raw/compressed") {
                EXPECT_EQ(v["format"], "png");
                EXPECT_EQ(v["data"]["length"], 17);
            } else {
                ADD_FAILURE() << "unexpected topic " << topic;
            }
        }
        EXPECT_EQ(seen.size(), 7u);
        for (const auto &[topic, n] : seen) EXPECT_EQ(n, frames) << topic;
    }
    fs::remove_all(dir);
}

// Bags from the reference writer: zstd and uncompressed chunks, with and without chunk
// indexes, and messages outside chunks: every pixel read back.
TEST_F(McapReference, ReadsWhatTheReferenceWriterWrites) {
    const fs::path dir = tempDir("writer");
    const std::vector<std::pair<std::string, std::string>> cases{
        {"zstd", "--compression zstd"},
        {"none", "--compression none"},
        {"zstd_no_chunk_index", "--compression zstd --no-chunk-index"},
        {"no_chunks", "--no-chunks"},
    };
    for (const auto &[name, args] : cases) {
        SCOPED_TRACE(name);
        const fs::path file = dir / (name + ".mcap");
        int status = 0;
        test::runCommand("cd " + quoted(test::nodeFolder()) + " && node write_reference.cjs " + quoted(file.string()) + " " +
                             args + " --frames 6 --width 64 --height 48 --disparity 8",
                         status);
        ASSERT_EQ(status, 0);
        mcap::Reader r(file.string());
        EXPECT_EQ(r.indexed(), name == "zstd" || name == "none") << r.recoveryNote();
        EXPECT_EQ(r.statistics().message_count, 24u);
        for (int side = 0; side < 2; ++side) {
            const mcap::Channel *ch = r.channelByTopic(side ? "/stereo/right/image_raw" : "/stereo/left/image_raw");
            ASSERT_NE(ch, nullptr);
            int frame = 0;
            r.readMessages(
                [&](const mcap::MessageView &m) {
                    const ros2::Image img = ros2::decodeImage(m.data, m.size);
                    img.checkLayout("reference");
                    const auto tex = test::referenceTexture(64 + 8, 48, frame);
                    int wrong = 0;
                    for (int y = 0; y < 48; ++y)
                        for (int x = 0; x < 64; ++x)
                            wrong += img.data[y * img.step + x] != test::referencePixel(tex, 64, 8, side, x, y);
                    EXPECT_EQ(wrong, 0) << "frame " << frame;
                    EXPECT_EQ(img.header.stamp.ns(), 1700000000000000000LL + frame * 50000000LL + side * 1000000LL);
                    ++frame;
                    return true;
                },
                {ch->id});
            EXPECT_EQ(frame, 6);
        }
        const mcap::Channel *info = r.channelByTopic("/stereo/right/camera_info");
        ASSERT_NE(info, nullptr);
        r.readMessages(
            [&](const mcap::MessageView &m) {
                const auto ci = ros2::decodeCameraInfo(m.data, m.size);
                EXPECT_DOUBLE_EQ(ci.p[3], -100 * 0.12);
                return false;
            },
            {info->id});
    }
    fs::remove_all(dir);
}
