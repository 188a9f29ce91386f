// SPDX-License-Identifier: MIT
// Tests of the videre1394 source: the class the plugin exports, linked with the fake
// IEEE-1394 bus and driven through the host's wrappers (settings validated as a rig's
// are), plus the splitting and the stored-calibration parser on their own.
#include "fake_dc1394.hpp"
#include "svs_calibration.hpp"
#include "videre_source.hpp"

#include "source_under_test.hpp"

#include "config/rig_config.hpp"
#include "core/calibration.hpp"
#include "core/error.hpp"
#include "host/plugin_host.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

using binocle::LentFrame;
using binocle::Source;
using binocle::test::Failure;
using binocle::test::failureOf;
using binocle::test::inside;
using binocle::test::maxDiff;
using namespace binocle::videre1394;

namespace {

constexpr uint64_t kGuid = 0x00b09d0100a1b2c3ULL; // the fake Videre head's

fake::FakeBus &fakes() { return fake::fakeBus(); }

const binocle::PluginRecord &record() { return binocle::test::inProcessSource<VidereSource>("videre1394"); }

std::unique_ptr<Source> make(const std::string &yaml = "{}") { return binocle::test::makeSource(record(), yaml); }

std::unique_ptr<Source> started(const std::string &yaml = "{}") { return binocle::test::startSource(record(), yaml); }

// An SVS parameter text as a Videre head stores it: calibrated at 640x480 with 8 mm
// lenses (769.23 px at 10.4 um) on a 150 mm baseline.
const char *kStoredCalibration = R"(# SVS Engine v 4.0 Stereo Camera Parameter File

[image]
max_linelen 640
max_lines 480
width 640
height 480
decimation 1

[stereo]
ndisp 48
corrxsize 11

[external]
Tx -150.120000
Ty 0.310000
Tz -0.520000
Rx 0.002100
Ry -0.004300
Rz 0.000700

[left camera]
pwidth 640
pheight 480
dpx 0.010400
dpy 0.010400
sx 1.000000
Cx 322.400000
Cy 241.700000
f 769.230000
fy 770.100000
alpha 0.000000
kappa1 -0.081000
kappa2 0.052000
kappa3 0.000000
tau1 0.000400
tau2 -0.000300
proj
  7.700000e+02 0.000000e+00 3.200000e+02 0.000000e+00
  0.000000e+00 7.700000e+02 2.400000e+02 0.000000e+00
  0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00
rect
  1.0 0.0 0.0
  0.0 1.0 0.0
  0.0 0.0 1.0

[right camera]
pwidth 640
pheight 480
dpx 0.010400
dpy 0.010400
sx 1.000000
Cx 318.900000
Cy 239.200000
f 771.500000
fy 772.000000
alpha 0.000000
kappa1 -0.079000
kappa2 0.049000
kappa3 0.000000
tau1 0.000000
tau2 0.000000
proj
  7.700000e+02 0.000000e+00 3.200000e+02 -1.155924e+05
  0.000000e+00 7.700000e+02 2.400000e+02 0.000000e+00
  0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00
)";

class Videre : public ::testing::Test {
protected:
    void SetUp() override {
        fakes().reset();
        fakes().add(fake::Head{});
    }
};

// ---- Splitting ---------------------------------------------------------------------------

TEST(VidereSplit, LibdcPutsTheFirstByteInMemoryInTheFirstImage) {
    // Two 16-bit pixels per line, two lines: bytes (first, second) of each pixel.
    std::vector<uint8_t> frame{10, 20, 11, 21, 12, 22, 13, 23};
    std::vector<uint8_t> scratch;
    splitInterleaved(frame.data(), 2, 2, 4, 1, /*leftIsFirstByte=*/false, scratch);
    // Left image (the second bytes) first, then the right image (the first bytes).
    EXPECT_EQ(frame, (std::vector<uint8_t>{20, 21, 22, 23, 10, 11, 12, 13}));

    std::vector<uint8_t> again{10, 20, 11, 21, 12, 22, 13, 23};
    splitInterleaved(again.data(), 2, 2, 4, 1, /*leftIsFirstByte=*/true, scratch);
    EXPECT_EQ(again, (std::vector<uint8_t>{10, 11, 12, 13, 20, 21, 22, 23}));
}

TEST(VidereSplit, PaddedLinesAndDecimationByTwo) {
    // 4x2 pixels, 2 bytes of padding per line; left bytes 0..7, right bytes 100..107.
    const uint32_t stride = 4 * 2 + 2;
    std::vector<uint8_t> frame(stride * 2, 0xEE);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x) {
            frame[y * stride + 2 * x] = static_cast<uint8_t>(100 + 4 * y + x); // first byte: right
            frame[y * stride + 2 * x + 1] = static_cast<uint8_t>(4 * y + x);    // second byte: left
        }
    std::vector<uint8_t> scratch;
    splitInterleaved(frame.data(), 4, 2, stride, 2, false, scratch);
    // 2x1 images of 2x2 block means: left (0+1+4+5)/4 = 2.5, (2+3+6+7)/4 = 4.5.
    EXPECT_NEAR(frame[0], 2.5, 0.5);
    EXPECT_NEAR(frame[1], 4.5, 0.5);
    EXPECT_NEAR(frame[2], 102.5, 0.5);
    EXPECT_NEAR(frame[3], 104.5, 0.5);
}

// ---- Streaming ---------------------------------------------------------------------------

TEST_F(Videre, DeliversLeftAndRightFromTheInterleavedFrameInTheDmaBuffer) {
    auto src = started("video_mode: 640x480_MONO16\nfps: 30");
    EXPECT_EQ(fakes().counters(kGuid).mode, "640x480_MONO16");
    EXPECT_EQ(fakes().counters(kGuid).fps, 30);
    for (uint64_t n = 0; n < 3; ++n) {
        auto f = src->grab(1000);
        ASSERT_TRUE(f);
        EXPECT_EQ(f->raw().sequence, n);
        EXPECT_EQ(f->raw().left.format, BINOCLE_PIXEL_GRAY8);
        EXPECT_EQ(f->raw().left.width, 640);
        EXPECT_EQ(f->raw().left.height, 480);
        EXPECT_EQ(maxDiff(f->left(), fake::pattern(640, 480, n, 1)), 0) << "frame " << n;
        EXPECT_EQ(maxDiff(f->right(), fake::pattern(640, 480, n, 2)), 0) << "frame " << n;
        EXPECT_EQ(f->raw().timestamp_left_ns, f->raw().timestamp_right_ns);
        // The images live in the DMA buffer, which stays out of the ring while lent.
        EXPECT_TRUE(inside(f->raw().left.data, fakes().counters(kGuid).bufferMemory));
        EXPECT_TRUE(inside(f->raw().right.data, fakes().counters(kGuid).bufferMemory));
        EXPECT_EQ(fakes().counters(kGuid).inRing, 3u);
    }
    EXPECT_EQ(fakes().counters(kGuid).inRing, 4u);
    EXPECT_EQ(fakes().counters(kGuid).enqueued, 3u);
    const YAML::Node st = YAML::Load(src->statistics());
    EXPECT_EQ(st["frames"].as<int>(), 3);
    EXPECT_EQ(st["enqueued_on_release"].as<int>(), 3);
    EXPECT_EQ(st["guid"].as<std::string>(), "0x00b09d0100a1b2c3");
    EXPECT_TRUE(st["live"].as<bool>()); // a camera: the host's default policy is latest
}

TEST_F(Videre, LeftByteSaysWhichByteIsLeftAndGettingItWrongSwapsTheImages) {
    fakes().change(kGuid, [](fake::Head &h) { h.leftFirst = true; });
    {
        auto src = started("left_byte: first");
        auto f = src->grab(1000);
        ASSERT_TRUE(f);
        EXPECT_EQ(maxDiff(f->left(), fake::pattern(640, 480, 0, 1)), 0);
        EXPECT_EQ(maxDiff(f->right(), fake::pattern(640, 480, 0, 2)), 0);
    }
    auto wrong = started("left_byte: second");
    auto g = wrong->grab(1000);
    ASSERT_TRUE(g);
    EXPECT_EQ(maxDiff(g->right(), fake::pattern(640, 480, 1, 1)), 0);
    EXPECT_EQ(maxDiff(g->left(), fake::pattern(640, 480, 1, 2)), 0);
}

TEST_F(Videre, PaddedLinesAreSplitLineByLine) {
    fakes().change(kGuid, [](fake::Head &h) { h.padding = 32; });
    auto src = started();
    auto f = src->grab(1000);
    ASSERT_TRUE(f);
    EXPECT_EQ(maxDiff(f->left(), fake::pattern(640, 480, 0, 1)), 0);
    EXPECT_EQ(maxDiff(f->right(), fake::pattern(640, 480, 0, 2)), 0);
}

TEST_F(Videre, DecimationByFourGivesThePapers320x240FromThe1280x960Sensor) {
    auto src = started("video_mode: 1280x960_MONO16\nfps: 7.5\ndecimation: 4");
    auto f = src->grab(1000);
    ASSERT_TRUE(f);
    ASSERT_EQ(f->raw().left.width, 320);
    ASSERT_EQ(f->raw().left.height, 240);
    const cv::Mat full[2] = {fake::pattern(1280, 960, 0, 1), fake::pattern(1280, 960, 0, 2)};
    const cv::Mat got[2] = {f->left(), f->right()};
    int checked = 0;
    for (int side = 0; side < 2; ++side)
        for (int v = 0; v < 240; v += 17)
            for (int u = 0; u < 320; u += 13) {
                double sum = 0;
                for (int dy = 0; dy < 4; ++dy)
                    for (int dx = 0; dx < 4; ++dx) sum += full[side].at<uint8_t>(4 * v + dy, 4 * u + dx);
                EXPECT_NEAR(got[side].at<uint8_t>(v, u), sum / 16, 1.0) << "side " << side << " at " << u << "," << v;
                ++checked;
            }
    EXPECT_GT(checked, 500);
    EXPECT_EQ(YAML::Load(src->statistics())["image_size"].as<std::string>(), "320x240");
}

TEST_F(Videre, Format7ModesIgnoreFps) {
    auto src = started("video_mode: format7_0\nfps: 0\ndecimation: 4");
    auto f = src->grab(1000);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->raw().left.width, 320);
}

// ---- Stored calibration -------------------------------------------------------------------

TEST_F(Videre, TheStoredCalibrationIsPublishedScaledToTheDecimatedImages) {
    fakes().change(kGuid, [](fake::Head &h) { h.storedCalibration = kStoredCalibration; });
    auto src = make("video_mode: 1280x960_MONO16\nfps: 7.5\ndecimation: 4");
    const std::string yaml = src->calibration();
    ASSERT_FALSE(yaml.empty());
    // The framework reads it as any calibration file.
    const auto cal = binocle::StereoCalibration::fromYaml(yaml, "videre stored calibration");
    EXPECT_EQ(cal.image_size, cv::Size(320, 240));
    EXPECT_NEAR(cal.baselineMm(), std::sqrt(150.12 * 150.12 + 0.31 * 0.31 + 0.52 * 0.52), 1e-9);
    EXPECT_NEAR(cal.T.at<double>(0), -150.12, 1e-9);
    // 640x480 -> 320x240 halves the focal lengths; principal points keep their pixel centre.
    EXPECT_NEAR(cal.M1.at<double>(0, 0), 769.23 / 2, 1e-9);
    EXPECT_NEAR(cal.M1.at<double>(1, 1), 770.10 / 2, 1e-9);
    EXPECT_NEAR(cal.M1.at<double>(0, 2), (322.4 + 0.5) / 2 - 0.5, 1e-9);
    EXPECT_NEAR(cal.M1.at<double>(1, 2), (241.7 + 0.5) / 2 - 0.5, 1e-9);
    EXPECT_NEAR(cal.M2.at<double>(0, 0), 771.5 / 2, 1e-9);
    EXPECT_NEAR(cal.D1.at<double>(0), -0.081, 1e-12);  // kappa1
    EXPECT_NEAR(cal.D1.at<double>(2), 0.0004, 1e-12);  // tau1
    EXPECT_NEAR(cal.D1.at<double>(3), -0.0003, 1e-12); // tau2
    EXPECT_NEAR(cal.R.at<double>(0, 2), -0.0043, 1e-5); // Rodrigues of (Rx, Ry, Rz)
    EXPECT_NEAR(cal.R.at<double>(1, 0), 0.0007, 1e-5);
    // The rectified focal length stays close to the cameras' own.
    EXPECT_NEAR(cal.focalLengthPx(), 769.23 / 2, 0.03 * 769.23 / 2);
    EXPECT_EQ(YAML::Load(src->statistics())["stored_calibration"].as<std::string>(), "stored in the head");
}

TEST_F(Videre, AHeadWithoutStoredCalibrationPublishesNone) {
    auto src = make();
    EXPECT_TRUE(src->calibration().empty());
    EXPECT_EQ(YAML::Load(src->statistics())["stored_calibration"].as<std::string>(), "none stored in the head");
    fakes().change(kGuid, [](fake::Head &h) { h.storedCalibration = kStoredCalibration; });
    EXPECT_TRUE(make("use_stored_calibration: false")->calibration().empty());
}

TEST_F(Videre, AnUnusableStoredCalibrationIsReportedButCaptureGoesOn) {
    std::string broken = kStoredCalibration;
    broken.replace(broken.find("f 771.500000"), 12, "focus 771.5");
    fakes().change(kGuid, [&](fake::Head &h) { h.storedCalibration = broken; });
    auto src = started();
    EXPECT_TRUE(src->calibration().empty());
    EXPECT_EQ(YAML::Load(src->statistics())["stored_calibration"].as<std::string>(),
              "unusable: [right camera] has no 'f'");
    EXPECT_TRUE(src->grab(1000));

    fakes().change(kGuid, [](fake::Head &h) { h.calibrationUnreadable = true; });
    auto other = make();
    EXPECT_TRUE(other->calibration().empty());
    EXPECT_NE(YAML::Load(other->statistics())["stored_calibration"].as<std::string>().find("unreadable"),
              std::string::npos);
}

TEST(VidereSvs, ParseErrorsNameTheLineSectionAndKey) {
    auto message = [](const std::string &text) {
        try {
            parseSvs(text);
        } catch (const std::invalid_argument &e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(message("f 1\n"), "no [section] at all: not an SVS calibration text");
    EXPECT_EQ(message("[left camera]\nf abc\n"), "line 2: [left camera] f 'abc' is not a number");
    EXPECT_EQ(message("[left camera]\npwidth 640\npheight 480\nf 500\nCx 320\n"), "[left camera] has no 'cy'");
    std::string noTx = kStoredCalibration;
    noTx.replace(noTx.find("Tx -150.120000"), 14, "");
    EXPECT_EQ(message(noTx), "[external] has no 'tx'");
    // A size that is not a scaling of the calibrated one is refused.
    try {
        calibrationYaml(parseSvs(kStoredCalibration), 320, 200, "");
        FAIL() << "320x200 accepted for a 640x480 calibration";
    } catch (const std::invalid_argument &e) {
        EXPECT_STREQ(e.what(), "it was made at 640x480, which does not scale to the delivered 320x200");
    }
}

// ---- Bad input -----------------------------------------------------------------------------

TEST_F(Videre, NoBusNoCameraAndUnknownGuidAreClearErrors) {
    fakes().setNoBus(true);
    Failure f = failureOf([] { make(); });
    EXPECT_EQ(f.code, BINOCLE_ERR_NOT_FOUND) << f.message;
    EXPECT_NE(f.message.find("videre1394: no IEEE-1394 bus found (dc1394_new failed)"), std::string::npos) << f.message;

    fakes().reset();
    f = failureOf([] { make(); });
    EXPECT_EQ(f.code, BINOCLE_ERR_NOT_FOUND) << f.message;
    EXPECT_NE(f.message.find("videre1394: no IEEE-1394 camera found (bus: fake bus with no camera)"), std::string::npos)
        << f.message;

    fakes().add(fake::Head{});
    f = failureOf([] { make("guid: 0x1234"); });
    EXPECT_EQ(f.code, BINOCLE_ERR_NOT_FOUND) << f.message;
    EXPECT_NE(f.message.find("no camera with GUID 0x0000000000001234 (found: 0x00b09d0100a1b2c3 Videre Design MDS-STH)"),
              std::string::npos)
        << f.message;

    f = failureOf([] { make("guid: videre-left"); });
    EXPECT_EQ(f.code, BINOCLE_ERR_INVALID_ARGUMENT) << f.message;
    EXPECT_NE(f.message.find("guid = 'videre-left': expected a hexadecimal GUID"), std::string::npos) << f.message;

    // By GUID, in upper case and without 0x: found.
    EXPECT_NO_THROW(make("guid: 00B09D0100A1B2C3"));
}

TEST_F(Videre, WithoutGuidTheFirstVidereHeadIsChosenAndOtherCamerasAreNot) {
    fakes().reset();
    fake::Head flea;
    flea.info = {0x00b09d01aaaa0001ULL, 0, "Point Grey Research", "Flea2 FL2-08S2M"};
    fakes().add(flea);
    Failure f = failureOf([] { make(); });
    EXPECT_EQ(f.code, BINOCLE_ERR_NOT_FOUND) << f.message;
    EXPECT_NE(f.message.find("no Videre Design head among the IEEE-1394 cameras (found: 0x00b09d01aaaa0001 Point "
                             "Grey Research Flea2 FL2-08S2M); set guid"),
              std::string::npos)
        << f.message;
    fakes().add(fake::Head{});
    auto src = make();
    EXPECT_EQ(YAML::Load(src->statistics())["model"].as<std::string>(), "MDS-STH");
}

TEST_F(Videre, ModesFrameRatesAndDecimationTheHeadCannotDoAreRefused) {
    Failure f = failureOf([] { make("video_mode: 1024x768_MONO16"); });
    EXPECT_EQ(f.code, BINOCLE_ERR_UNSUPPORTED) << f.message;
    EXPECT_NE(f.message.find("camera 0x00b09d0100a1b2c3 Videre Design MDS-STH cannot do video_mode 1024x768_MONO16: "
                             "it offers 640x480_MONO16 (7.5, 15, 30 fps); 1280x960_MONO16 (3.75, 7.5, 15 fps); "
                             "640x480_MONO8 (15, 30 fps); format7_0 (1280x960 MONO16)"),
              std::string::npos)
        << f.message;

    f = failureOf([] { make("video_mode: 640x480_MONO8"); });
    EXPECT_EQ(f.code, BINOCLE_ERR_UNSUPPORTED) << f.message;
    EXPECT_NE(f.message.find("video_mode 640x480_MONO8 carries MONO8 pixels"), std::string::npos) << f.message;

    f = failureOf([] { make("video_mode: 640x480_MONO16\nfps: 60"); });
    EXPECT_EQ(f.code, BINOCLE_ERR_UNSUPPORTED) << f.message;
    EXPECT_NE(f.message.find("cannot do fps 60 in video_mode 640x480_MONO16: it offers 7.5, 15, 30 fps"),
              std::string::npos)
        << f.message;

    f = failureOf([] { make("decimation: 7"); });
    EXPECT_EQ(f.code, BINOCLE_ERR_INVALID_ARGUMENT) << f.message;
    EXPECT_NE(f.message.find("decimation = 7: expected a divisor of 640 and 480"), std::string::npos) << f.message;
    EXPECT_EQ(fakes().counters(kGuid).opened, fakes().counters(kGuid).closed);
}

TEST_F(Videre, AFrameOfTheWrongSizeIsRefusedAndGivenBack) {
    fakes().change(kGuid, [](fake::Head &h) { h.deliverWidth = 320; });
    auto src = started();
    const Failure f = failureOf([&] { src->grab(1000); });
    EXPECT_EQ(f.code, BINOCLE_ERR_DEVICE) << f.message;
    EXPECT_NE(f.message.find("camera 0x00b09d0100a1b2c3 Videre Design MDS-STH delivered a 320x480 frame of 16-bit pixels "
                             "(307200 bytes), expected 640x480 of 16-bit pixels (614400 bytes) for 640x480_MONO16"),
              std::string::npos)
        << f.message;
    EXPECT_EQ(fakes().counters(kGuid).inRing, 4u);
}

// ---- Buffers, a camera that goes away, one that says nothing ------------------------------------

TEST_F(Videre, DmaBuffersAreEnqueuedWhenTheFrameIsReleasedFromAnyThread) {
    auto src = started("buffer_count: 3");
    auto a = src->grab(1000);
    auto b = src->grab(1000);
    EXPECT_EQ(fakes().counters(kGuid).enqueued, 0u);
    EXPECT_EQ(fakes().counters(kGuid).inRing, 1u);
    const Failure busy = failureOf([&] { src->grab(1000); });
    EXPECT_EQ(busy.code, BINOCLE_ERR_BUSY) << busy.message;
    EXPECT_NE(busy.message.find("2 of the 3 DMA buffers"), std::string::npos) << busy.message;
    std::thread([frame = std::move(a)]() mutable { frame.reset(); }).join();
    EXPECT_EQ(fakes().counters(kGuid).enqueued, 1u);
    EXPECT_EQ(fakes().counters(kGuid).inRing, 2u);
    auto c = src->grab(1000);
    ASSERT_TRUE(c);
    EXPECT_EQ(maxDiff(c->left(), fake::pattern(640, 480, 2, 1)), 0);
}

TEST_F(Videre, StopKeepsTheRingUntilTheLastLentFrameComesBack) {
    auto src = started();
    auto f = src->grab(1000);
    src->stop();
    EXPECT_FALSE(fakes().counters(kGuid).transmitting);
    EXPECT_EQ(fakes().counters(kGuid).stops, 0u);
    EXPECT_EQ(maxDiff(f->left(), fake::pattern(640, 480, 0, 1)), 0); // still valid
    f.reset();
    EXPECT_EQ(fakes().counters(kGuid).stops, 1u);
    EXPECT_EQ(fakes().counters(kGuid).stopsWithFramesOut, 0u);
    src->start();
    EXPECT_EQ(fakes().counters(kGuid).setups, 2u);
    EXPECT_TRUE(src->grab(1000));
}

TEST_F(Videre, CorruptFramesAreSkippedAndCounted) {
    fakes().change(kGuid, [](fake::Head &h) { h.corrupt = {0}; });
    auto src = started();
    auto f = src->grab(1000);
    ASSERT_TRUE(f);
    EXPECT_EQ(maxDiff(f->left(), fake::pattern(640, 480, 1, 1)), 0);
    EXPECT_EQ(YAML::Load(src->statistics())["corrupt"].as<int>(), 1);
}

TEST_F(Videre, ACameraVanishingMidCaptureGivesADeviceErrorAndNoHang) {
    fakes().change(kGuid, [](fake::Head &h) { h.vanishAfter = 2; });
    auto src = started();
    auto first = src->grab(1000);
    auto second = src->grab(1000);
    ASSERT_TRUE(second);
    const auto t0 = std::chrono::steady_clock::now();
    const Failure gone = failureOf([&] { src->grab(5000); });
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
    EXPECT_EQ(gone.code, BINOCLE_ERR_DEVICE) << gone.message;
    EXPECT_NE(gone.message.find("camera 0x00b09d0100a1b2c3 Videre Design MDS-STH stopped delivering after 2 frames"),
              std::string::npos)
        << gone.message;
    const Failure again = failureOf([&] { src->grab(5000); });
    EXPECT_EQ(again.code, BINOCLE_ERR_DEVICE) << again.message;
    // Frames lent before are given back without harm, and the source goes away cleanly.
    first.reset();
    second.reset();
    src.reset();
    EXPECT_EQ(fakes().counters(kGuid).opened, fakes().counters(kGuid).closed);
}

TEST_F(Videre, ASilentHeadTimesOutWithinTheTimeout) {
    fakes().change(kGuid, [](fake::Head &h) { h.stalled = true; });
    auto src = started();
    const auto t0 = std::chrono::steady_clock::now();
    const Failure late = failureOf([&] { src->grab(100); });
    const auto waited = std::chrono::steady_clock::now() - t0;
    EXPECT_EQ(late.code, BINOCLE_ERR_TIMEOUT) << late.message;
    EXPECT_NE(late.message.find("no frame from camera 0x00b09d0100a1b2c3 Videre Design MDS-STH within 100 ms "
                                "(640x480_MONO16 at 15 fps)"),
              std::string::npos)
        << late.message;
    EXPECT_GE(waited, std::chrono::milliseconds(90));
    EXPECT_LT(waited, std::chrono::seconds(2));
    fakes().change(kGuid, [](fake::Head &h) { h.stalled = false; });
    EXPECT_TRUE(src->grab(1000));
}

TEST_F(Videre, EnumerateDevicesListsGuidVendorAndModel) {
    const YAML::Node list = YAML::Load(Source::enumerateDevices(record()));
    ASSERT_EQ(list.size(), 1u);
    EXPECT_EQ(list[0]["id"].as<std::string>(), "0x00b09d0100a1b2c3");
    EXPECT_EQ(list[0]["vendor"].as<std::string>(), "Videre Design");
    EXPECT_EQ(list[0]["model"].as<std::string>(), "MDS-STH");
    EXPECT_EQ(list[0]["description"].as<std::string>(), "Videre Design MDS-STH");
    EXPECT_TRUE(list[0]["videre"].as<bool>());
    fakes().setNoBus(true);
    EXPECT_EQ(YAML::Load(Source::enumerateDevices(record())).size(), 0u);
}

} // namespace
