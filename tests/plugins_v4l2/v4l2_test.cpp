// SPDX-License-Identifier: MIT
// Tests of the v4l2 source: the class the plugin exports, linked with the fake device
// layer and driven through the host's wrappers (settings validated as a rig's are).
#include "fake_v4l2.hpp"
#include "v4l2_source.hpp"

#include "source_under_test.hpp"

#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "host/plugin_host.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

using binocle::LentFrame;
using binocle::Source;
using binocle::test::Failure;
using binocle::test::failureOf;
using binocle::test::inside;
using binocle::test::maxDiff;
using namespace binocle::v4l2;

namespace {

fake::FakeSystem &fakes() { return fake::fakeSystem(); }

const binocle::PluginRecord &record() { return binocle::test::inProcessSource<V4l2Source>("v4l2"); }

std::unique_ptr<Source> make(const std::string &yaml) { return binocle::test::makeSource(record(), yaml); }

std::unique_ptr<Source> started(const std::string &yaml) { return binocle::test::startSource(record(), yaml); }

fake::Camera grey(const std::string &path, int seed, uint32_t w = 64, uint32_t h = 48) {
    return fake::camera(path, {fake::offer(V4L2_PIX_FMT_GREY, {{w, h}})}, seed);
}

fake::Camera yuyv(const std::string &path, int seed, uint32_t w = 64, uint32_t h = 48) {
    return fake::camera(path, {fake::offer(V4L2_PIX_FMT_YUYV, {{w, h}})}, seed);
}

YAML::Node stats(Source &s) { return YAML::Load(s.statistics()); }

// Settings of most tests: two small GREY devices.
const std::string kGrey = "pixel_format: grey\nwidth: 64\nheight: 48\n";

class V4l2 : public ::testing::Test {
protected:
    void SetUp() override { fakes().reset(); }
    // /dev/video0 (pattern seed 1) and /dev/video1 (seed 2), GREY 64x48.
    static void addGreyPair() {
        fakes().add(grey("/dev/video0", 1));
        fakes().add(grey("/dev/video1", 2));
    }
};

// ---- Streaming ---------------------------------------------------------------------------

TEST_F(V4l2, TwoGreyDevicesDeliverPairsInMappedBuffersWithoutCopy) {
    auto left = grey("/dev/video0", 1), right = grey("/dev/video1", 2);
    right.firstTimestampNs += 2000000; // 2 ms later than the left
    fakes().add(left);
    fakes().add(right);
    auto src = started(kGrey + "buffer_count: 4");

    for (uint64_t n = 0; n < 3; ++n) {
        auto f = src->grab(1000);
        ASSERT_TRUE(f);
        EXPECT_EQ(f->raw().sequence, n);
        EXPECT_EQ(f->raw().left.format, BINOCLE_PIXEL_GRAY8);
        EXPECT_EQ(maxDiff(f->left(), fake::pattern(64, 48, n, 1)), 0) << "frame " << n;
        EXPECT_EQ(maxDiff(f->right(), fake::pattern(64, 48, n, 2)), 0) << "frame " << n;
        EXPECT_EQ(f->raw().timestamp_right_ns - f->raw().timestamp_left_ns, 2000000);
        // The pixels are the driver's buffers themselves.
        EXPECT_TRUE(inside(f->raw().left.data, fakes().counters("/dev/video0").bufferMemory));
        EXPECT_TRUE(inside(f->raw().right.data, fakes().counters("/dev/video1").bufferMemory));
        EXPECT_EQ(fakes().counters("/dev/video0").inDriver, 3u); // one of four lent
        EXPECT_EQ(fakes().counters("/dev/video1").inDriver, 3u);
    }
    // Released frames went back to the drivers.
    EXPECT_EQ(fakes().counters("/dev/video0").inDriver, 4u);
    EXPECT_EQ(fakes().counters("/dev/video1").inDriver, 4u);
    EXPECT_EQ(fakes().counters("/dev/video0").queueCalls, 4u + 3u);
    YAML::Node st = stats(*src);
    EXPECT_EQ(st["frames"].as<int>(), 3);
    EXPECT_TRUE(st["zero_copy"].as<bool>());
    EXPECT_EQ(st["unpaired"].as<int>(), 0);
    EXPECT_TRUE(st["live"].as<bool>()); // a camera: the host's default policy is latest
}

TEST_F(V4l2, ALentBufferReleasedFromAnotherThreadIsQueuedAgain) {
    addGreyPair();
    auto src = started(kGrey + "buffer_count: 4");
    auto f = src->grab(1000);
    ASSERT_TRUE(f);
    const uint32_t before = fakes().counters("/dev/video0").queueCalls;
    std::thread([frame = std::move(f)]() mutable { frame.reset(); }).join();
    EXPECT_EQ(fakes().counters("/dev/video0").queueCalls, before + 1);
    EXPECT_EQ(fakes().counters("/dev/video0").inDriver, 4u);
    EXPECT_EQ(fakes().counters("/dev/video1").inDriver, 4u);
}

TEST_F(V4l2, HoldingAllButOneBufferRefusesWithBusyUntilOneComesBack) {
    addGreyPair();
    auto src = started(kGrey + "buffer_count: 3");
    auto a = src->grab(1000);
    auto b = src->grab(1000);
    const Failure busy = failureOf([&] { src->grab(1000); });
    EXPECT_EQ(busy.code, BINOCLE_ERR_BUSY) << busy.message;
    EXPECT_NE(busy.message.find("2 of the 3 buffers of /dev/video0"), std::string::npos) << busy.message;
    EXPECT_NE(busy.message.find("buffer_count"), std::string::npos) << busy.message;
    a.reset();
    auto c = src->grab(1000);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->raw().sequence, 2u);
}

TEST_F(V4l2, YuyvBecomesGrayFromTheLumaAndBgrByBt601) {
    fakes().add(yuyv("/dev/video0", 1));
    fakes().add(yuyv("/dev/video1", 2));
    {
        auto src = started("pixel_format: yuyv\ncolor: gray\nwidth: 64\nheight: 48");
        auto f = src->grab(1000);
        ASSERT_TRUE(f);
        EXPECT_EQ(f->raw().left.format, BINOCLE_PIXEL_GRAY8);
        EXPECT_EQ(maxDiff(f->left(), fake::pattern(64, 48, 0, 1)), 0);
        EXPECT_EQ(maxDiff(f->right(), fake::pattern(64, 48, 0, 2)), 0);
        // A conversion makes new pixels and gives the buffer back at once.
        EXPECT_FALSE(inside(f->raw().left.data, fakes().counters("/dev/video0").bufferMemory));
        EXPECT_EQ(fakes().counters("/dev/video0").inDriver, 4u);
        EXPECT_FALSE(stats(*src)["zero_copy"].as<bool>());
    }
    // Colour: constant chroma U = 90, V = 200 over a luma ramp.
    for (const char *path : {"/dev/video0", "/dev/video1"})
        fakes().change(path, [](fake::Camera &c) {
            c.content = [](uint64_t, const PixFormat &f) {
                return fake::yuyvBytes(fake::pattern(f.width, f.height, 0, 0), 90, 200, f.bytesPerLine);
            };
        });
    auto src = started("pixel_format: yuyv\ncolor: bgr\nwidth: 64\nheight: 48");
    auto f = src->grab(1000);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->raw().left.format, BINOCLE_PIXEL_BGR8);
    const cv::Mat bgr = f->left();
    const cv::Mat luma = fake::pattern(64, 48, 0, 0);
    int checked = 0;
    for (int y = 0; y < 48; y += 7)
        for (int x = 0; x < 64; x += 5) {
            // BT.601 video range: Y below 16 is black.
            const double yy = 1.164 * std::max(luma.at<uint8_t>(y, x) - 16, 0), u = 90 - 128, v = 200 - 128;
            auto clamp = [](double c) { return std::min(255.0, std::max(0.0, c)); };
            const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
            EXPECT_NEAR(p[2], clamp(yy + 1.596 * v), 2.0) << "R at " << x << "," << y;
            EXPECT_NEAR(p[1], clamp(yy - 0.813 * v - 0.391 * u), 2.0) << "G at " << x << "," << y;
            EXPECT_NEAR(p[0], clamp(yy + 2.018 * u), 2.0) << "B at " << x << "," << y;
            ++checked;
        }
    EXPECT_GT(checked, 50);
}

TEST_F(V4l2, MjpegFramesAreDecoded) {
    // Left: a smooth grey ramp; right: red above, blue below.
    cv::Mat ramp(48, 64, CV_8UC1);
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x) ramp.at<uint8_t>(y, x) = static_cast<uint8_t>(2 * x + y);
    cv::Mat colours(48, 64, CV_8UC3, cv::Scalar(0, 0, 200));
    colours.rowRange(24, 48).setTo(cv::Scalar(200, 0, 0));
    auto left = fake::camera("/dev/video0", {fake::offer(V4L2_PIX_FMT_MJPEG, {{64, 48}})});
    auto right = fake::camera("/dev/video1", {fake::offer(V4L2_PIX_FMT_MJPEG, {{64, 48}})});
    left.content = [ramp](uint64_t, const PixFormat &) { return fake::mjpegBytes(ramp); };
    right.content = [colours](uint64_t, const PixFormat &) { return fake::mjpegBytes(colours); };
    fakes().add(left);
    fakes().add(right);

    auto gray = started("pixel_format: mjpeg\ncolor: gray\nwidth: 64\nheight: 48");
    auto f = gray->grab(1000);
    ASSERT_TRUE(f);
    EXPECT_LE(maxDiff(f->left(), ramp), 3); // JPEG at quality 100: nearly lossless
    f.reset();
    gray.reset();

    auto bgr = started("pixel_format: mjpeg\ncolor: bgr\nwidth: 64\nheight: 48");
    auto g = bgr->grab(1000);
    ASSERT_TRUE(g);
    const cv::Vec3b top = g->right().at<cv::Vec3b>(5, 30), bottom = g->right().at<cv::Vec3b>(40, 30);
    EXPECT_NEAR(top[2], 200, 6);
    EXPECT_LT(top[0], 10);
    EXPECT_NEAR(bottom[0], 200, 6);
    EXPECT_LT(bottom[2], 10);
}

TEST_F(V4l2, SideBySideGreyIsSplitInHalvesOfTheSameBuffer) {
    fakes().add(grey("/dev/video2", 3, 128, 48));
    auto src = started("layout: side_by_side\ndevice_left: /dev/video2\npixel_format: grey\nwidth: 128\nheight: 48");
    auto f = src->grab(1000);
    ASSERT_TRUE(f);
    const cv::Mat whole = fake::pattern(128, 48, 0, 3);
    EXPECT_EQ(f->raw().left.width, 64);
    EXPECT_EQ(f->raw().right.width, 64);
    EXPECT_EQ(maxDiff(f->left(), whole.colRange(0, 64)), 0);
    EXPECT_EQ(maxDiff(f->right(), whole.colRange(64, 128)), 0);
    EXPECT_EQ(static_cast<uint8_t *>(f->raw().right.data), static_cast<uint8_t *>(f->raw().left.data) + 64);
    EXPECT_EQ(f->raw().left.stride_bytes, 128);
    EXPECT_EQ(f->raw().timestamp_left_ns, f->raw().timestamp_right_ns);
    EXPECT_TRUE(inside(f->raw().left.data, fakes().counters("/dev/video2").bufferMemory));
}

TEST_F(V4l2, SideBySideSwapsHalvesAndConvertsYuyv) {
    fakes().add(yuyv("/dev/video2", 3, 128, 48));
    auto src = started("layout: side_by_side\ndevice_left: /dev/video2\nswap_halves: true\n"
                       "pixel_format: yuyv\nwidth: 128\nheight: 48");
    auto f = src->grab(1000);
    ASSERT_TRUE(f);
    const cv::Mat whole = fake::pattern(128, 48, 0, 3);
    EXPECT_EQ(maxDiff(f->left(), whole.colRange(64, 128)), 0);
    EXPECT_EQ(maxDiff(f->right(), whole.colRange(0, 64)), 0);
}

// ---- Pairing -----------------------------------------------------------------------------

TEST_F(V4l2, AFrameTheOtherDeviceDroppedIsCountedUnpaired) {
    auto right = grey("/dev/video1", 2);
    right.dropped = {2};
    fakes().add(grey("/dev/video0", 1));
    fakes().add(right);
    auto src = started(kGrey);
    const std::vector<uint64_t> expected{0, 1, 3, 4};
    for (uint64_t n : expected) {
        auto f = src->grab(1000);
        ASSERT_TRUE(f);
        EXPECT_EQ(maxDiff(f->left(), fake::pattern(64, 48, n, 1)), 0) << "left of frame " << n;
        EXPECT_EQ(maxDiff(f->right(), fake::pattern(64, 48, n, 2)), 0) << "right of frame " << n;
        EXPECT_EQ(f->raw().timestamp_left_ns, f->raw().timestamp_right_ns);
    }
    YAML::Node st = stats(*src);
    EXPECT_EQ(st["frames"].as<int>(), 4);
    EXPECT_EQ(st["unpaired_left"].as<int>(), 1);
    EXPECT_EQ(st["unpaired_right"].as<int>(), 0);
    EXPECT_EQ(st["unpaired"].as<int>(), 1);
}

TEST_F(V4l2, DevicesStartingOutOfStepArePairedWithinTheTolerance) {
    // 30 fps; the right device's frame n is stamped 40 ms after the left's frame n, so
    // the left frame n + 1 (33.3 ms later) is its partner, 6.7 ms apart.
    auto right = grey("/dev/video1", 2);
    right.firstTimestampNs += 40000000;
    fakes().add(grey("/dev/video0", 1));
    fakes().add(right);
    auto src = started(kGrey + "fps: 30");
    for (uint64_t n = 0; n < 3; ++n) {
        auto f = src->grab(1000);
        ASSERT_TRUE(f);
        EXPECT_EQ(maxDiff(f->left(), fake::pattern(64, 48, n + 1, 1)), 0);
        EXPECT_EQ(maxDiff(f->right(), fake::pattern(64, 48, n, 2)), 0);
        EXPECT_NEAR(static_cast<double>(f->raw().timestamp_right_ns - f->raw().timestamp_left_ns), 6.67e6, 0.01e6);
    }
    EXPECT_EQ(stats(*src)["unpaired_left"].as<int>(), 1);
    EXPECT_NEAR(stats(*src)["pair_tolerance_ms"].as<double>(), 16.67, 0.01);

    // A tolerance tighter than their offset pairs nothing: a clear error, not a hang.
    src.reset();
    auto strict = started(kGrey + "fps: 30\npair_tolerance_ms: 1");
    const auto t0 = std::chrono::steady_clock::now();
    const Failure never = failureOf([&] { strict->grab(200); });
    EXPECT_TRUE(never.code == BINOCLE_ERR_TIMEOUT || never.code == BINOCLE_ERR_DEVICE) << never.message;
    EXPECT_NE(never.message.find("pair_tolerance_ms 1"), std::string::npos) << never.message;
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
}

TEST_F(V4l2, CorruptBuffersAreSkippedAndCounted) {
    auto left = grey("/dev/video0", 1), right = grey("/dev/video1", 2);
    left.corrupt = {1};
    right.corrupt = {1};
    fakes().add(left);
    fakes().add(right);
    auto src = started(kGrey);
    for (uint64_t n : {0, 2}) {
        auto f = src->grab(1000);
        ASSERT_TRUE(f);
        EXPECT_EQ(maxDiff(f->left(), fake::pattern(64, 48, n, 1)), 0);
        EXPECT_EQ(maxDiff(f->right(), fake::pattern(64, 48, n, 2)), 0);
    }
    EXPECT_EQ(stats(*src)["devices"][0]["corrupt"].as<int>(), 1);
    EXPECT_EQ(stats(*src)["unpaired"].as<int>(), 0);
}

// ---- Bad input -----------------------------------------------------------------------------

TEST_F(V4l2, AMissingDeviceIsNamed) {
    const Failure none = failureOf([] { make("device_left: /dev/video0"); });
    EXPECT_EQ(none.code, BINOCLE_ERR_NOT_FOUND) << none.message;
    EXPECT_NE(none.message.find("/dev/video0: no such device"), std::string::npos) << none.message;
    EXPECT_NE(none.message.find("no V4L2 device on this machine"), std::string::npos) << none.message;

    fakes().add(grey("/dev/video0", 1));
    fakes().add(grey("/dev/video4", 1));
    const Failure right = failureOf([] { make("device_left: /dev/video0\ndevice_right: /dev/video1\npixel_format: grey\nwidth: 64\nheight: 48"); });
    EXPECT_EQ(right.code, BINOCLE_ERR_NOT_FOUND) << right.message;
    EXPECT_NE(right.message.find("/dev/video1: no such device"), std::string::npos) << right.message;
    EXPECT_NE(right.message.find("V4L2 devices here: /dev/video0, /dev/video4"), std::string::npos) << right.message;
    // Nothing stays open after a failed create.
    EXPECT_EQ(fakes().counters("/dev/video0").opened, fakes().counters("/dev/video0").closed);
}

TEST_F(V4l2, ABusyDeviceIsNamed) {
    auto left = grey("/dev/video0", 1);
    left.busy = true;
    fakes().add(left);
    fakes().add(grey("/dev/video1", 2));
    const Failure busy = failureOf([] { make(kGrey); });
    EXPECT_EQ(busy.code, BINOCLE_ERR_BUSY) << busy.message;
    EXPECT_NE(busy.message.find("/dev/video0 is busy (EBUSY in VIDIOC_S_FMT)"), std::string::npos) << busy.message;
}

TEST_F(V4l2, AFormatTheDeviceCannotDeliverListsWhatItOffers) {
    fakes().add(fake::camera("/dev/video2", {fake::offer(V4L2_PIX_FMT_YUYV, {{640, 480}, {320, 240}}),
                                              fake::offer(V4L2_PIX_FMT_MJPEG, {{640, 480}})}));
    const Failure f = failureOf([] {
        make("layout: side_by_side\ndevice_left: /dev/video2\npixel_format: mjpeg\nwidth: 1280\nheight: 480");
    });
    EXPECT_EQ(f.code, BINOCLE_ERR_UNSUPPORTED) << f.message;
    EXPECT_NE(f.message.find("/dev/video2 cannot deliver MJPG 1280x480: it offers YUYV 640x480, 320x240; MJPG 640x480"),
              std::string::npos)
        << f.message;
    EXPECT_NE(f.message.find("the driver proposed MJPG 640x480"), std::string::npos) << f.message;

    const Failure g = failureOf([] {
        make("layout: side_by_side\ndevice_left: /dev/video2\npixel_format: grey\nwidth: 640\nheight: 480");
    });
    EXPECT_EQ(g.code, BINOCLE_ERR_UNSUPPORTED) << g.message;
    EXPECT_NE(g.message.find("/dev/video2 cannot deliver GREY 640x480: it offers YUYV"), std::string::npos) << g.message;
}

TEST_F(V4l2, ANodeThatIsNotAVideoCaptureDeviceIsRefused) {
    auto meta = grey("/dev/video1", 0);
    meta.capabilities = V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING;
    meta.card = "UVC metadata";
    fakes().add(grey("/dev/video0", 1));
    fakes().add(meta);
    const Failure f = failureOf([] { make(kGrey); });
    EXPECT_EQ(f.code, BINOCLE_ERR_UNSUPPORTED) << f.message;
    EXPECT_NE(f.message.find("/dev/video1 (UVC metadata, driver uvcvideo) is not a video capture device"),
              std::string::npos)
        << f.message;
}

TEST_F(V4l2, SettingsThatContradictEachOtherAreRefused) {
    fakes().add(grey("/dev/video0", 1, 65, 48));
    const Failure same = failureOf([] { make("device_left: /dev/video0\ndevice_right: /dev/video0"); });
    EXPECT_EQ(same.code, BINOCLE_ERR_INVALID_ARGUMENT) << same.message;
    EXPECT_NE(same.message.find("device_right = /dev/video0"), std::string::npos) << same.message;
    const Failure odd = failureOf([] { make("layout: side_by_side\ndevice_left: /dev/video0\nwidth: 65\nheight: 48"); });
    EXPECT_EQ(odd.code, BINOCLE_ERR_INVALID_ARGUMENT) << odd.message;
    EXPECT_NE(odd.message.find("width = 65: expected an even width"), std::string::npos) << odd.message;
}

TEST_F(V4l2, AFrameOfTheWrongSizeIsAnErrorNamingDeviceAndSizes) {
    auto left = yuyv("/dev/video0", 1);
    left.content = [](uint64_t n, const PixFormat &f) {
        auto bytes = fake::yuyvBytes(fake::pattern(f.width, f.height, n, 1), 128, 128, f.bytesPerLine);
        if (n == 1) bytes.resize(100);
        return bytes;
    };
    fakes().add(left);
    fakes().add(yuyv("/dev/video1", 2));
    auto src = started("pixel_format: yuyv\nwidth: 64\nheight: 48");
    EXPECT_TRUE(src->grab(1000));
    const Failure f = failureOf([&] { src->grab(1000); });
    EXPECT_EQ(f.code, BINOCLE_ERR_DEVICE) << f.message;
    EXPECT_NE(f.message.find("/dev/video0 delivered a frame of 100 bytes (driver sequence 1), expected 6144 for "
                             "YUYV 64x48 (128 bytes per line)"),
              std::string::npos)
        << f.message;
    EXPECT_EQ(fakes().counters("/dev/video0").inDriver, 4u); // the bad buffer went back
    // The stream goes on with the next frame.
    auto g = src->grab(1000);
    ASSERT_TRUE(g);
    EXPECT_EQ(maxDiff(g->left(), fake::pattern(64, 48, 2, 1)), 0);
}

// ---- A device that goes away, one that says nothing -------------------------------------------

TEST_F(V4l2, ADeviceVanishingMidStreamGivesADeviceErrorAndNoHang) {
    auto right = grey("/dev/video1", 2);
    right.vanishAfter = 3;
    fakes().add(grey("/dev/video0", 1));
    fakes().add(right);
    auto src = started(kGrey);
    std::unique_ptr<LentFrame> held;
    for (int n = 0; n < 3; ++n) held = src->grab(1000);
    ASSERT_TRUE(held); // a frame lent from the device that is about to vanish

    const auto t0 = std::chrono::steady_clock::now();
    const Failure gone = failureOf([&] { src->grab(5000); });
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
    EXPECT_EQ(gone.code, BINOCLE_ERR_DEVICE) << gone.message;
    // Whoever meets ENODEV first (giving a frame back, or taking the next) tells.
    EXPECT_NE(gone.message.find("/dev/video1 went away (ENODEV in VIDIOC_"), std::string::npos) << gone.message;
    EXPECT_NE(gone.message.find("right, after 3 frames"), std::string::npos) << gone.message;
    // Every later grab says the same, at once.
    const Failure again = failureOf([&] { src->grab(5000); });
    EXPECT_EQ(again.code, BINOCLE_ERR_DEVICE);
    EXPECT_NE(again.message.find("/dev/video1 went away"), std::string::npos) << again.message;
    EXPECT_NE(stats(*src)["devices"][1]["gone"].as<std::string>().find("went away"), std::string::npos);
    // Giving back the frame lent before is harmless; so are stop and destroy.
    held.reset();
    src->stop();
    src.reset();
    EXPECT_EQ(fakes().counters("/dev/video1").opened, fakes().counters("/dev/video1").closed);
}

TEST_F(V4l2, AnUnpluggedSideBySideDeviceIsNamed) {
    fakes().add(yuyv("/dev/video2", 3, 128, 48));
    auto src = started("layout: side_by_side\ndevice_left: /dev/video2\npixel_format: yuyv\nwidth: 128\nheight: 48");
    EXPECT_TRUE(src->grab(1000));
    fakes().unplug("/dev/video2");
    const Failure gone = failureOf([&] { src->grab(1000); });
    EXPECT_EQ(gone.code, BINOCLE_ERR_DEVICE) << gone.message;
    EXPECT_NE(gone.message.find("/dev/video2 went away"), std::string::npos) << gone.message;
}

TEST_F(V4l2, ASilentDeviceTimesOutWithinTheTimeoutAndTheStreamGoesOnAfter) {
    auto right = grey("/dev/video1", 2);
    right.stalled = true;
    fakes().add(grey("/dev/video0", 1));
    fakes().add(right);
    auto src = started(kGrey);
    const auto t0 = std::chrono::steady_clock::now();
    const Failure late = failureOf([&] { src->grab(100); });
    const auto waited = std::chrono::steady_clock::now() - t0;
    EXPECT_EQ(late.code, BINOCLE_ERR_TIMEOUT) << late.message;
    EXPECT_NE(late.message.find("no frame from /dev/video1 (right) within 100 ms"), std::string::npos) << late.message;
    EXPECT_GE(waited, std::chrono::milliseconds(90));
    EXPECT_LT(waited, std::chrono::seconds(2));

    fakes().change("/dev/video1", [](fake::Camera &c) { c.stalled = false; });
    auto f = src->grab(1000);
    ASSERT_TRUE(f);
    EXPECT_EQ(maxDiff(f->left(), fake::pattern(64, 48, 0, 1)), 0);
    EXPECT_EQ(maxDiff(f->right(), fake::pattern(64, 48, 0, 2)), 0);
}

// ---- Life cycle ------------------------------------------------------------------------------

TEST_F(V4l2, AFrameLentAcrossStopAndStartIsQueuedWhenItComesBack) {
    addGreyPair();
    auto src = started(kGrey + "buffer_count: 4");
    auto f = src->grab(1000);
    src->stop();
    EXPECT_EQ(fakes().counters("/dev/video0").inDriver, 0u);
    src->start();
    EXPECT_EQ(fakes().counters("/dev/video0").inDriver, 3u);
    EXPECT_EQ(maxDiff(f->left(), fake::pattern(64, 48, 0, 1)), 0); // still valid
    f.reset();
    EXPECT_EQ(fakes().counters("/dev/video0").inDriver, 4u);
    EXPECT_TRUE(src->grab(1000));
    src.reset();
    const fake::Counters c = fakes().counters("/dev/video0");
    EXPECT_EQ(c.mapped, c.unmapped);
    EXPECT_EQ(c.opened, c.closed);
}

TEST_F(V4l2, AStartThatFailsOnOneDeviceCanBeRetried) {
    addGreyPair();
    auto src = make(kGrey);
    fakes().change("/dev/video1", [](fake::Camera &c) { c.busy = true; }); // taken meanwhile
    const Failure busy = failureOf([&] { src->start(); });
    EXPECT_EQ(busy.code, BINOCLE_ERR_BUSY) << busy.message;
    EXPECT_NE(busy.message.find("/dev/video1 is busy (EBUSY in VIDIOC_REQBUFS)"), std::string::npos) << busy.message;
    fakes().change("/dev/video1", [](fake::Camera &c) { c.busy = false; });
    src->start();
    auto f = src->grab(1000);
    ASSERT_TRUE(f);
    EXPECT_EQ(maxDiff(f->left(), fake::pattern(64, 48, 0, 1)), 0);
    EXPECT_EQ(maxDiff(f->right(), fake::pattern(64, 48, 0, 2)), 0);
}

TEST_F(V4l2, GrabBeforeStartIsRefused) {
    addGreyPair();
    auto src = make(kGrey);
    const Failure f = failureOf([&] { src->grab(100); });
    EXPECT_EQ(f.code, BINOCLE_ERR_INVALID_ARGUMENT) << f.message;
    EXPECT_NE(f.message.find("grab before start"), std::string::npos) << f.message;
}

TEST_F(V4l2, EnumerateDevicesListsPathsCardsAndFormats) {
    EXPECT_EQ(YAML::Load(Source::enumerateDevices(record())).size(), 0u);
    fakes().add(fake::camera("/dev/video0", {fake::offer(V4L2_PIX_FMT_YUYV, {{640, 480}, {320, 240}}),
                                              fake::offer(V4L2_PIX_FMT_MJPEG, {{1280, 480}})}));
    auto meta = grey("/dev/video1", 0);
    meta.capabilities = V4L2_CAP_META_CAPTURE;
    fakes().add(meta);
    const YAML::Node list = YAML::Load(Source::enumerateDevices(record()));
    ASSERT_EQ(list.size(), 2u);
    EXPECT_EQ(list[0]["id"].as<std::string>(), "/dev/video0");
    EXPECT_NE(list[0]["description"].as<std::string>().find("Fake Stereo Camera (uvcvideo"), std::string::npos);
    EXPECT_TRUE(list[0]["capture"].as<bool>());
    ASSERT_EQ(list[0]["formats"].size(), 2u);
    EXPECT_EQ(list[0]["formats"][0].as<std::string>(), "YUYV 640x480, 320x240");
    EXPECT_EQ(list[0]["formats"][1].as<std::string>(), "MJPG 1280x480");
    EXPECT_FALSE(list[1]["capture"].as<bool>());
}

} // namespace
