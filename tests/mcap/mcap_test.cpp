// SPDX-License-Identifier: MIT
// Binocle::mcap by itself: write then read every message type under each compression, a
// writer cut at every point, and each kind of bad file refused with file, offset and cause.
#include <binocle/mcap.hpp>
#include <binocle/ros2_messages.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace binocle;

namespace {

fs::path tempDir(const std::string &name) {
    fs::path d = fs::temp_directory_path() / ("binocle_mcap_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::vector<uint8_t> slurp(const fs::path &p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}
void spit(const fs::path &p, const std::vector<uint8_t> &b, size_t n = SIZE_MAX) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char *>(b.data()), static_cast<std::streamsize>(std::min(n, b.size())));
}

std::vector<uint8_t> pattern(size_t n, int seed) {
    std::vector<uint8_t> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = static_cast<uint8_t>((i * 7 + seed * 13 + (i >> 5)) & 0xFF);
    return v;
}

ros2::Image image(int w, int h, const std::string &enc, const std::vector<uint8_t> &px, int64_t ns) {
    ros2::Image m;
    m.header.stamp = ros2::Time::fromNs(ns);
    m.header.frame_id = "left_optical";
    m.width = w;
    m.height = h;
    m.encoding = enc;
    m.step = static_cast<uint32_t>(w * ros2::Image::bytesPerPixel(enc));
    m.data = px.data();
    m.size = px.size();
    return m;
}

// A small bag: `frames` images on two topics and camera infos; returns the image bytes.
std::vector<std::vector<uint8_t>> writeBag(const fs::path &file, mcap::WriterOptions o, int frames, bool close = true) {
    mcap::Writer w(file.string(), o);
    const uint16_t is = w.addSchema(ros2::Image::kType, "ros2msg", ros2::definition(ros2::Image::kType));
    const uint16_t cs = w.addSchema(ros2::CameraInfo::kType, "ros2msg", ros2::definition(ros2::CameraInfo::kType));
    const uint16_t left = w.addChannel(is, "/cam/left/image_raw", "cdr");
    const uint16_t right = w.addChannel(is, "/cam/right/image_raw", "cdr");
    const uint16_t info = w.addChannel(cs, "/cam/left/camera_info", "cdr");
    std::vector<std::vector<uint8_t>> images;
    for (int i = 0; i < frames; ++i) {
        const int64_t t = 1000000000LL + i * 33000000LL;
        for (uint16_t ch : {left, right}) {
            images.push_back(pattern(32 * 24, i * 2 + (ch == right)));
            const auto bytes = ros2::encode(image(32, 24, "mono8", images.back(), t));
            w.write(ch, static_cast<uint32_t>(i), static_cast<uint64_t>(t), static_cast<uint64_t>(t), bytes.data(), bytes.size());
        }
        ros2::CameraInfo ci;
        ci.header.stamp = ros2::Time::fromNs(t);
        ci.width = 32;
        ci.height = 24;
        ci.d = {0.1, -0.2, 0, 0, 0.01};
        ci.k = {100, 0, 16, 0, 100, 12, 0, 0, 1};
        const auto bytes = ros2::encode(ci);
        w.write(info, static_cast<uint32_t>(i), static_cast<uint64_t>(t), static_cast<uint64_t>(t), bytes.data(), bytes.size());
    }
    if (close) w.close();
    return images;
}

std::vector<std::vector<uint8_t>> readImages(const mcap::Reader &r) {
    std::vector<std::vector<uint8_t>> out;
    std::vector<uint16_t> ids;
    for (const char *t : {"/cam/left/image_raw", "/cam/right/image_raw"})
        if (const mcap::Channel *c = r.channelByTopic(t)) ids.push_back(c->id);
    r.readMessages(
        [&](const mcap::MessageView &m) {
            const ros2::Image img = ros2::decodeImage(m.data, m.size);
            img.checkLayout("test");
            out.emplace_back(img.data, img.data + img.size);
            return true;
        },
        ids);
    return out;
}

std::string errorOf(const std::function<void()> &f) {
    try {
        f();
    } catch (const std::exception &e) {
        return e.what();
    }
    return "(no error)";
}

} // namespace

TEST(Mcap, RoundTripEachCompression) {
    const fs::path dir = tempDir("roundtrip");
    for (auto c : {mcap::Compression::Zstd, mcap::Compression::Lz4, mcap::Compression::None}) {
        SCOPED_TRACE(mcap::compressionName(c));
        const fs::path file = dir / (std::string("bag_") + mcap::compressionName(c) + ".mcap");
        mcap::WriterOptions o;
        o.compression = c;
        o.chunk_bytes = 4000; // several chunks
        const auto images = writeBag(file, o, 12);
        mcap::Reader r(file.string());
        EXPECT_TRUE(r.indexed()) << r.recoveryNote();
        EXPECT_EQ(r.profile(), "ros2");
        EXPECT_EQ(r.statistics().message_count, 36u);
        EXPECT_GT(r.chunks().size(), 3u);
        EXPECT_EQ(r.statistics().chunk_count, r.chunks().size());
        EXPECT_EQ(r.statistics().message_start_time, 1000000000u);
        EXPECT_EQ(r.chunks().front().compression, mcap::compressionName(c));
        EXPECT_EQ(readImages(r), images);
        const mcap::Channel *info = r.channelByTopic("/cam/left/camera_info");
        ASSERT_NE(info, nullptr);
        EXPECT_EQ(r.schemaOf(*info)->name, "sensor_msgs/msg/CameraInfo");
        int infos = 0;
        r.readMessages(
            [&](const mcap::MessageView &m) {
                const auto ci = ros2::decodeCameraInfo(m.data, m.size);
                EXPECT_EQ(ci.d, (std::vector<double>{0.1, -0.2, 0, 0, 0.01}));
                EXPECT_EQ(ci.k[2], 16);
                ++infos;
                return true;
            },
            {info->id});
        EXPECT_EQ(infos, 12);
    }
    fs::remove_all(dir);
}

TEST(Mcap, SeekByTimeReadsOnlyThatSpan) {
    const fs::path dir = tempDir("seek");
    mcap::WriterOptions o;
    o.chunk_bytes = 2000;
    writeBag(dir / "b.mcap", o, 20);
    mcap::Reader r((dir / "b.mcap").string());
    std::vector<uint64_t> times;
    r.readMessages([&](const mcap::MessageView &m) { times.push_back(m.log_time); return true; },
                   {r.channelByTopic("/cam/left/image_raw")->id}, 1000000000u + 5 * 33000000u, 1000000000u + 9 * 33000000u);
    ASSERT_EQ(times.size(), 5u);
    EXPECT_EQ(times.front(), 1000000000u + 5 * 33000000u);
    fs::remove_all(dir);
}

TEST(Mcap, ExistingFileIsNeverOverwritten) {
    const fs::path dir = tempDir("exists");
    spit(dir / "x.mcap", {1, 2, 3});
    EXPECT_NE(errorOf([&] { mcap::Writer w((dir / "x.mcap").string()); }).find("never overwritten"), std::string::npos);
    EXPECT_EQ(slurp(dir / "x.mcap").size(), 3u);
    fs::remove_all(dir);
}

// A writer stopped at any byte: the reader recovers exactly the messages of the chunks
// that are whole on disk, and says it scanned.
TEST(Mcap, CutAtEveryPointRecoversEveryCompleteChunk) {
    const fs::path dir = tempDir("cut");
    mcap::WriterOptions o;
    o.chunk_bytes = 3000;
    o.sync_chunks = false;
    writeBag(dir / "full.mcap", o, 10);
    const auto bytes = slurp(dir / "full.mcap");
    // Where each chunk ends (its message indexes included), and how many messages it holds.
    mcap::Reader full((dir / "full.mcap").string());
    std::vector<std::pair<uint64_t, uint64_t>> ends; // end of chunk record, messages up to it
    uint64_t count = 0;
    for (size_t i = 0; i < full.chunks().size(); ++i) {
        const auto &k = full.chunks()[i];
        full.readMessages([&](const mcap::MessageView &m) { count += m.chunk_offset == static_cast<int64_t>(k.offset); return true; },
                          {}, k.message_start_time, k.message_end_time);
        ends.emplace_back(k.offset + k.length, count);
    }
    ASSERT_GT(ends.size(), 3u);
    for (size_t cut = 40; cut < bytes.size(); cut += 41) { // after the Header record
        spit(dir / "cut.mcap", bytes, cut);
        mcap::Reader r((dir / "cut.mcap").string());
        uint64_t expected = 0;
        for (const auto &[end, n] : ends)
            if (end <= cut) expected = n;
        SCOPED_TRACE("cut at " + std::to_string(cut));
        EXPECT_FALSE(r.indexed());
        EXPECT_NE(r.recoveryNote().find("scanned the data section"), std::string::npos);
        EXPECT_EQ(r.statistics().message_count, expected) << r.recoveryNote();
        uint64_t read = 0;
        r.readMessages([&](const mcap::MessageView &) { ++read; return true; });
        EXPECT_EQ(read, expected);
    }
    fs::remove_all(dir);
}

// A process killed (SIGKILL) while writing leaves a file with every flushed chunk.
TEST(Mcap, WriterKilledLeavesItsChunks) {
    const fs::path dir = tempDir("kill");
    const fs::path file = dir / "k.mcap";
    int pipefd[2];
    ASSERT_EQ(::pipe(pipefd), 0);
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(pipefd[0]);
        mcap::WriterOptions o;
        o.chunk_bytes = 1; // a chunk per message
        mcap::Writer w(file.string(), o);
        const uint16_t s = w.addSchema(ros2::Image::kType, "ros2msg", ros2::definition(ros2::Image::kType));
        const uint16_t c = w.addChannel(s, "/a/left/image_raw", "cdr");
        const auto px = pattern(64, 1);
        for (uint32_t i = 0;; ++i) {
            const auto b = ros2::encode(image(8, 8, "mono8", px, i));
            w.write(c, i, i, i, b.data(), b.size());
            if (i == 20) (void)!::write(pipefd[1], "x", 1);
        }
    }
    ::close(pipefd[1]);
    char x;
    ASSERT_EQ(::read(pipefd[0], &x, 1), 1);
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    mcap::Reader r(file.string());
    EXPECT_FALSE(r.indexed());
    EXPECT_GE(r.statistics().message_count, 21u) << r.recoveryNote();
    uint64_t n = 0;
    r.readMessages([&](const mcap::MessageView &m) {
        EXPECT_EQ(m.log_time, n++);
        ros2::decodeImage(m.data, m.size).checkLayout("killed");
        return true;
    });
    EXPECT_EQ(n, r.statistics().message_count);
    fs::remove_all(dir);
}

// ---- Bad files ---------------------------------------------------------------------------

class McapBad : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = tempDir("bad");
        mcap::WriterOptions o;
        o.compression = mcap::Compression::None;
        o.chunk_bytes = 2500;
        writeBag(dir_ / "good.mcap", o, 6);
        bytes_ = slurp(dir_ / "good.mcap");
        mcap::Reader r((dir_ / "good.mcap").string());
        chunk_ = r.chunks()[1];
    }
    void TearDown() override { fs::remove_all(dir_); }
    // Writes `b` as bad.mcap and returns the error of opening and reading it all.
    std::string readError(const std::vector<uint8_t> &b) {
        spit(dir_ / "bad.mcap", b);
        return errorOf([&] {
            mcap::Reader r((dir_ / "bad.mcap").string());
            r.readMessages([](const mcap::MessageView &m) {
                ros2::decodeImage(m.data, m.size);
                return true;
            }, {0, 1});
        });
    }
    static void put64(std::vector<uint8_t> &b, size_t at, uint64_t v) {
        for (int i = 0; i < 8; ++i) b[at + i] = static_cast<uint8_t>(v >> (8 * i));
    }
    fs::path dir_;
    std::vector<uint8_t> bytes_;
    mcap::ChunkInfo chunk_;
};

TEST_F(McapBad, NotAnMcapFile) {
    auto b = bytes_;
    b[1] = 'X';
    const std::string e = readError(b);
    EXPECT_NE(e.find("bad.mcap"), std::string::npos) << e;
    EXPECT_NE(e.find("does not start with the MCAP magic"), std::string::npos) << e;
    EXPECT_NE(readError({}).find("expected an MCAP file"), std::string::npos);
}

// A file refused while opening leaves no descriptor open: a replay that tries many files,
// or a fuzzer, would otherwise run out of them (found by mcap_reader_fuzz in CI).
TEST_F(McapBad, RefusedFileLeavesNoDescriptorOpen) {
    auto countFds = [] {
        return std::distance(fs::directory_iterator("/proc/self/fd"), fs::directory_iterator{});
    };
    auto b = bytes_;
    b[1] = 'X';
    spit(dir_ / "bad.mcap", b);
    const auto before = countFds();
    for (int i = 0; i < 50; ++i) {
        EXPECT_THROW(mcap::Reader((dir_ / "bad.mcap").string()), mcap::Error);
        EXPECT_THROW(mcap::Reader(dir_.string()), mcap::Error); // not a regular file
    }
    EXPECT_EQ(countFds(), before);
}

TEST_F(McapBad, ChunkCrcMismatchNamesTheChunk) {
    auto b = bytes_;
    b[chunk_.offset + chunk_.length - 100] ^= 0x55; // a byte of the records (uncompressed)
    const std::string e = readError(b);
    EXPECT_NE(e.find("record at offset " + std::to_string(chunk_.offset)), std::string::npos) << e;
    EXPECT_NE(e.find("CRC"), std::string::npos) << e;
    EXPECT_NE(e.find("damaged"), std::string::npos) << e;
}

TEST_F(McapBad, SummaryCrcMismatch) {
    auto b = bytes_;
    b[b.size() - 8 - 29 - 20] ^= 1; // inside the summary offsets
    const std::string e = readError(b);
    EXPECT_NE(e.find("summary"), std::string::npos) << e;
    EXPECT_NE(e.find("CRC"), std::string::npos) << e;
}

TEST_F(McapBad, ChunkWhoseRecordsLengthLies) {
    // The records length sits after 9 + 8 + 8 + 8 + 4 + 4 ("" compression) bytes.
    for (const uint64_t lie : {uint64_t{1} << 40, uint64_t{7}}) {
        auto b = bytes_;
        put64(b, chunk_.offset + 41, lie);
        const std::string e = readError(b);
        EXPECT_NE(e.find("record at offset " + std::to_string(chunk_.offset)), std::string::npos) << e;
        EXPECT_NE(e.find("chunk records"), std::string::npos) << e;
    }
}

TEST_F(McapBad, ChunkWhoseUncompressedSizeLies) {
    auto b = bytes_;
    put64(b, chunk_.offset + 9 + 16, uint64_t{1} << 50); // uncompressed_size: 1 PiB
    const std::string e = readError(b);
    EXPECT_NE(e.find("record at offset " + std::to_string(chunk_.offset)), std::string::npos) << e;
    EXPECT_NE(e.find("uncompressed_size"), std::string::npos) << e;
}

TEST_F(McapBad, RecordLengthBeyondTheFile) {
    auto b = bytes_;
    put64(b, chunk_.offset + 1, uint64_t{1} << 62);
    const std::string e = readError(b);
    EXPECT_NE(e.find("record at offset " + std::to_string(chunk_.offset)), std::string::npos) << e;
    EXPECT_NE(e.find("claims"), std::string::npos) << e;
}

TEST_F(McapBad, UnknownCompression) {
    // Rewrite with lz4 and rename it "xz4".
    mcap::WriterOptions o;
    o.compression = mcap::Compression::Lz4;
    writeBag(dir_ / "lz4.mcap", o, 3);
    auto b = slurp(dir_ / "lz4.mcap");
    for (size_t i = 0; i + 3 < b.size(); ++i)
        if (b[i] == 3 && b[i + 1] == 0 && b[i + 4] == 'l' && b[i + 5] == 'z' && b[i + 6] == '4') {
            b[i + 4] = 'x'; // in the first chunk only (the summary's CRC stays right)
            break;
        }
    const std::string e = readError(b);
    EXPECT_NE(e.find("unknown compression 'xz4'"), std::string::npos) << e;
    EXPECT_NE(e.find("expected zstd, lz4"), std::string::npos) << e;
}

TEST_F(McapBad, ImageStepOrSizeDisagreeingWithData) {
    const auto px = pattern(32 * 24, 0);
    auto m = image(32, 24, "mono8", px, 0);
    m.step = 31;
    EXPECT_NE(errorOf([&] { m.checkLayout("/cam/left/image_raw"); }).find("step 31 is less than width 32"), std::string::npos);
    m.step = 40;
    const std::string e = errorOf([&] { m.checkLayout("/cam/left/image_raw"); });
    EXPECT_NE(e.find("/cam/left/image_raw: data holds 768 bytes but step x height = 40 x 24 = 960"), std::string::npos) << e;
    m.step = 32;
    m.encoding = "yuv422";
    EXPECT_NE(errorOf([&] { m.checkLayout("t"); }).find("encoding 'yuv422' is not one Binocle reads"), std::string::npos);
}

TEST(Ros2Messages, CdrRoundTripOfEveryType) {
    const auto px = pattern(6 * 4 * 4, 3);
    ros2::DisparityImage d;
    d.header.frame_id = "left";
    d.header.stamp = ros2::Time::fromNs(1700000000123456789LL);
    d.image = image(6, 4, "32FC1", px, 5);
    d.f = 700.5f;
    d.t = 0.12f;
    d.min_disparity = 1;
    d.max_disparity = 64;
    d.delta_d = 0.0625f;
    const auto db = ros2::encode(d);
    const auto d2 = ros2::decodeDisparityImage(db.data(), db.size());
    EXPECT_EQ(d2.header.stamp.sec, 1700000000);
    EXPECT_EQ(d2.header.stamp.nanosec, 123456789u);
    EXPECT_EQ(d2.image.encoding, "32FC1");
    EXPECT_EQ(std::vector<uint8_t>(d2.image.data, d2.image.data + d2.image.size), px);
    EXPECT_FLOAT_EQ(d2.f, 700.5f);
    EXPECT_FLOAT_EQ(d2.delta_d, 0.0625f);

    ros2::PointCloud2 pc;
    pc.width = 16;
    pc.fields = {{"x", 0, ros2::PointField::FLOAT32, 1}, {"y", 4, ros2::PointField::FLOAT32, 1}, {"z", 8, ros2::PointField::FLOAT32, 1}};
    pc.point_step = 12;
    pc.row_step = 192;
    const auto cloud = pattern(192, 9);
    pc.data = cloud.data();
    pc.size = cloud.size();
    const auto pb = ros2::encode(pc);
    const auto pc2 = ros2::decodePointCloud2(pb.data(), pb.size());
    ASSERT_EQ(pc2.fields.size(), 3u);
    EXPECT_EQ(pc2.fields[2].name, "z");
    EXPECT_EQ(pc2.fields[2].offset, 8u);
    EXPECT_EQ(std::vector<uint8_t>(pc2.data, pc2.data + pc2.size), cloud);

    ros2::DiagnosticArray a;
    a.status.push_back({ros2::DiagnosticStatus::OK, "binocle/planar_efficiency", "", "rig", {{"planar_efficiency", "0.71"}}});
    const auto ab = ros2::encode(a);
    const auto a2 = ros2::decodeDiagnosticArray(ab.data(), ab.size());
    ASSERT_EQ(a2.status.size(), 1u);
    EXPECT_EQ(a2.status[0].values[0].second, "0.71");

    ros2::CompressedImage c;
    c.format = "png";
    c.data = cloud.data();
    c.size = 10;
    const auto cb = ros2::encode(c);
    EXPECT_EQ(ros2::decodeCompressedImage(cb.data(), cb.size()).format, "png");

    // Cut short anywhere: an error naming the type and the field, never a crash.
    for (size_t n = 0; n < db.size(); n += 7) {
        const std::string e = errorOf([&] { ros2::decodeDisparityImage(db.data(), n); });
        EXPECT_NE(e.find("stereo_msgs/msg/DisparityImage"), std::string::npos) << e;
    }
}

TEST(Ros2Messages, DefinitionsCarryEveryDependency) {
    const std::string &d = ros2::definition("stereo_msgs/msg/DisparityImage");
    for (const char *dep : {"MSG: std_msgs/Header", "MSG: builtin_interfaces/Time", "MSG: sensor_msgs/Image",
                            "MSG: sensor_msgs/RegionOfInterest"})
        EXPECT_NE(d.find(dep), std::string::npos) << dep;
    EXPECT_EQ(d.find("MSG: std_msgs/Header"), d.rfind("MSG: std_msgs/Header")); // once
    EXPECT_THROW(ros2::definition("nav_msgs/msg/Odometry"), ros2::Error);
}

TEST(Ros2Messages, CameraInfoPairRoundTrip) {
    ros2::StereoCameraModel m;
    m.width = 640;
    m.height = 480;
    m.M1 = {700, 0, 320, 0, 700, 240, 0, 0, 1};
    m.M2 = {705, 0, 322, 0, 705, 241, 0, 0, 1};
    m.D1 = {0.01, -0.02, 0, 0, 0};
    m.D2 = {0.02, -0.01, 0, 0, 0};
    const double c = std::cos(0.01), s = std::sin(0.01);
    m.R1 = {c, 0, s, 0, 1, 0, -s, 0, c};
    m.R2 = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    m.P1 = {690, 0, 320, 0, 0, 690, 240, 0, 0, 0, 1, 0};
    m.P2 = {690, 0, 320, -690 * 120.0, 0, 690, 240, 0, 0, 0, 1, 0};
    const auto infos = ros2::cameraInfos(m);
    EXPECT_DOUBLE_EQ(infos[1].p[3], -690 * 0.12); // metres, as ROS has it
    EXPECT_EQ(infos[0].distortion_model, "plumb_bob");
    const auto b = ros2::stereoModel(infos[0], infos[1], "bag");
    EXPECT_NEAR(b.T[0], -120.0, 1e-9); // T = R2^T (Tx, 0, 0), R2 = I
    EXPECT_NEAR(b.T[2], 0.0, 1e-9);
    EXPECT_NEAR(b.R[2], s, 1e-12); // R = R2^T R1 = R1
    EXPECT_DOUBLE_EQ(b.P2[3], -690 * 120.0);
    auto noBaseline = infos;
    noBaseline[1].p[3] = 0;
    EXPECT_NE(errorOf([&] { ros2::stereoModel(noBaseline[0], noBaseline[1], "bag.mcap"); }).find("bag.mcap: right camera_info P(0,3) is 0"),
              std::string::npos);
}
