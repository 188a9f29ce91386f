// SPDX-License-Identifier: MIT
// The host's instance wrappers (Source, LentFrame, Matcher, CloudTransform, Evaluator)
// over the fixture plugins: frames are read in place and always given back, a source
// lives as long as one of its frames, and a plugin that throws or returns garbage
// becomes a binocle::PluginError carrying its message, never a crash.
#include "fixture_host.hpp"

#include "core/calibration.hpp"

#include <map>
#include <type_traits>

namespace binocle::test {
namespace {

using ::testing::HasSubstr;

constexpr const char *kDeliberate = "deliberate failure from throws plugin";

// mock_source's pattern: left(x, y) = (7x + 13y + 3 * sequence) mod 256, right(x) = left(x + d).
uint8_t mockPixel(int x, int y, uint64_t sequence) { return static_cast<uint8_t>((7 * x + 13 * y + 3 * sequence) & 0xff); }

// Counts the pixels of a mock_source frame that differ from the pattern.
int patternErrors(const LentFrame &frame, int d) {
    const cv::Mat l = frame.left(), r = frame.right();
    const uint64_t seq = frame.raw().sequence;
    int errors = 0;
    for (int y = 0; y < l.rows; ++y)
        for (int x = 0; x < l.cols; ++x) {
            errors += l.at<uint8_t>(y, x) != mockPixel(x, y, seq);
            errors += r.at<uint8_t>(y, x) != (x + d < l.cols ? mockPixel(x + d, y, seq) : 0);
        }
    return errors;
}

Source mockSource(const std::string &yaml = "{}") {
    return makeInstance<Source>("mock_source", BINOCLE_KIND_STEREO_SOURCE, yaml);
}

// ---- Source and LentFrame ------------------------------------------------------------------------

TEST(SourceInstance, FramesAreLentInPlaceAndAllReleased) {
    Source source = mockSource("{frames: 3, width: 40, height: 24, disparity_px: 5}");
    source.start();
    for (uint64_t i = 0; i < 3; ++i) {
        std::unique_ptr<LentFrame> frame = source.grab(100);
        ASSERT_TRUE(frame);
        EXPECT_EQ(frame->raw().sequence, i);
        EXPECT_EQ(frame->left().size(), cv::Size(40, 24));
        EXPECT_EQ(frame->left().type(), CV_8UC1);
        // No copy: the host's views point at the source's own buffers.
        YAML::Node meta = YAML::Load(frame->metadata());
        EXPECT_EQ(reinterpret_cast<uintptr_t>(frame->left().data), meta["left_data"].as<uintptr_t>());
        EXPECT_EQ(reinterpret_cast<uintptr_t>(frame->right().data), meta["right_data"].as<uintptr_t>());
        EXPECT_EQ(patternErrors(*frame, 5), 0);
        EXPECT_EQ(statistic(source, "lent"), static_cast<int64_t>(i + 1));
        EXPECT_EQ(statistic(source, "released"), static_cast<int64_t>(i));
    }
    EXPECT_EQ(source.grab(100), nullptr); // end of stream is not an error
    EXPECT_EQ(statistic(source, "lent"), 3);
    EXPECT_EQ(statistic(source, "released"), 3);
}

TEST(SourceInstance, LentFrameReleasesOnDestruction) {
    Source source = mockSource();
    std::vector<std::unique_ptr<LentFrame>> held;
    for (int i = 0; i < 3; ++i) held.push_back(source.grab());
    EXPECT_EQ(statistic(source, "lent"), 3);
    EXPECT_EQ(statistic(source, "released"), 0); // several frames lent at once
    held.erase(held.begin() + 1);
    EXPECT_EQ(statistic(source, "released"), 1);
    held.clear();
    EXPECT_EQ(statistic(source, "released"), 3);
}

TEST(SourceInstance, StaysAliveWhileAFrameIsLent) {
    Source probe = mockSource(); // another instance of the same plugin reads the process-wide counters
    const int64_t destroyed = statistic(probe, "instances_destroyed");
    const int64_t released = statistic(probe, "all_released");

    auto source = newInstance<Source>("mock_source", BINOCLE_KIND_STEREO_SOURCE, "{disparity_px: 3}");
    std::unique_ptr<LentFrame> frame = source->grab();
    ASSERT_TRUE(frame);
    source.reset(); // the wrapper goes; the plugin instance must not
    EXPECT_EQ(statistic(probe, "instances_destroyed"), destroyed);
    EXPECT_EQ(statistic(probe, "all_released"), released);
    EXPECT_EQ(patternErrors(*frame, 3), 0); // pixels still valid and unchanged

    frame.reset(); // release, then destroy
    EXPECT_EQ(statistic(probe, "all_released"), released + 1);
    EXPECT_EQ(statistic(probe, "instances_destroyed"), destroyed + 1);
}

TEST(SourceInstance, OutlivesThePluginHost) {
    auto host = std::make_unique<PluginHost>(std::vector<std::string>{BINOCLE_TEST_PLUGIN_DIR});
    host->scan();
    const PluginRecord &record = host->require("mock_source", BINOCLE_KIND_STEREO_SOURCE);
    Source source(record, paramsFromYaml(record));
    host.reset(); // records and the host's handles on the libraries go; the code must stay loaded
    std::unique_ptr<LentFrame> frame = source.grab();
    ASSERT_TRUE(frame);
    EXPECT_EQ(patternErrors(*frame, 4), 0);
}

TEST(SourceInstance, PublishesItsCalibration) {
    Source source = mockSource("{width: 80, height: 60, baseline_mm: 120, focal_length_px: 500}");
    const StereoCalibration c = StereoCalibration::fromYaml(source.calibration(), "mock_source");
    EXPECT_EQ(c.image_size, cv::Size(80, 60));
    EXPECT_DOUBLE_EQ(c.baselineMm(), 120.0);
    EXPECT_DOUBLE_EQ(c.focalLengthPx(), 500.0);
    EXPECT_TRUE(c.rectified);
    EXPECT_EQ(mockSource("{publish_calibration: false}").calibration(), "");
}

TEST(Instances, WrappersAreNotCopyable) {
    // Each wrapper owns its plugin instance: a copy would destroy it twice.
    EXPECT_FALSE(std::is_copy_constructible_v<Source>);
    EXPECT_FALSE(std::is_copy_constructible_v<Matcher>);
    EXPECT_FALSE(std::is_copy_constructible_v<CloudTransform>);
    EXPECT_FALSE(std::is_copy_constructible_v<Evaluator>);
    EXPECT_FALSE(std::is_copy_assignable_v<Matcher>);
}

// ---- Plugins that throw --------------------------------------------------------------------------

TEST(ThrowingPlugin, MatcherCreateFailureIsAPluginError) {
    const std::string what = pluginErrorOf(
        [] { makeInstance<Matcher>("throws", BINOCLE_KIND_MATCHER, "{throw_in_create: true}"); });
    EXPECT_THAT(what, HasSubstr(kDeliberate));
    EXPECT_THAT(what, HasSubstr("matcher plugin 'throws' (" + fixturePath("throws") + "): create failed (BINOCLE_ERR_INTERNAL)"));
}

TEST(ThrowingPlugin, MatcherCallsArePluginErrorsAndTheProcessGoesOn) {
    Matcher matcher = makeInstance<Matcher>("throws", BINOCLE_KIND_MATCHER);
    const cv::Mat left(16, 32, CV_8UC1, cv::Scalar(10)), right(16, 32, CV_8UC1, cv::Scalar(20));
    for (int attempt = 0; attempt < 2; ++attempt) {
        try {
            matcher.compute(left, right);
            FAIL() << "compute of the throws plugin returned";
        } catch (const PluginError &e) {
            EXPECT_THAT(e.what(), HasSubstr("compute failed (BINOCLE_ERR_INTERNAL): " + std::string(kDeliberate)));
            EXPECT_EQ(e.code(), BINOCLE_ERR_INTERNAL);
        }
    }
    EXPECT_THAT(pluginErrorOf([&] { matcher.disparityRange(); }), HasSubstr(kDeliberate));
}

TEST(ThrowingPlugin, SourceCallsArePluginErrors) {
    EXPECT_THAT(pluginErrorOf([] { makeInstance<Source>("throws_source", BINOCLE_KIND_STEREO_SOURCE, "{throw_in_create: true}"); }),
                HasSubstr(kDeliberate));
    Source source = makeInstance<Source>("throws_source", BINOCLE_KIND_STEREO_SOURCE);
    EXPECT_THAT(pluginErrorOf([&] { source.start(); }), HasSubstr("start failed (BINOCLE_ERR_INTERNAL): " + std::string(kDeliberate)));
    EXPECT_THAT(pluginErrorOf([&] { source.grab(10); }), HasSubstr("grab failed (BINOCLE_ERR_INTERNAL): " + std::string(kDeliberate)));
    EXPECT_THAT(pluginErrorOf([&] { source.calibration(); }), HasSubstr(kDeliberate));
    EXPECT_THAT(pluginErrorOf([&] { source.statistics(); }), HasSubstr(kDeliberate));
    EXPECT_THAT(pluginErrorOf([&] { source.stop(); }), HasSubstr(kDeliberate));
    EXPECT_THAT(pluginErrorOf([] { Source::enumerateDevices(fixture("throws_source", BINOCLE_KIND_STEREO_SOURCE)); }),
                HasSubstr(kDeliberate));
    // ~Source calls stop, which throws inside the plugin: the destructor must swallow it.
}

// ---- Plugins that return garbage -----------------------------------------------------------------

TEST(GarbagePlugin, MalformedFramesAreRefusedAndStillReleased) {
    const std::map<std::string, std::string> expected = {
        {"negative_width", "left image has an impossible size -16x8"},
        {"small_stride", "right image has stride 4 bytes, less than width 16 x 1 bytes"},
        {"null_data", "left image has no pixel data (NULL)"},
        {"size_mismatch", "left and right images differ: 16x8"},
        {"float_pixels", "left/right images must be GRAY8, BGR8 or RGB8"}};
    for (const auto &[defect, message] : expected) {
        SCOPED_TRACE(defect);
        Source source = makeInstance<Source>("garbage_source", BINOCLE_KIND_STEREO_SOURCE, "{defect: " + defect + "}");
        const std::string what = pluginErrorOf([&] { source.grab(10); });
        EXPECT_THAT(what, HasSubstr("source plugin 'garbage_source'"));
        EXPECT_THAT(what, HasSubstr("grab failed (BINOCLE_ERR_INTERNAL): returned an invalid frame: " + message));
        EXPECT_EQ(statistic(source, "lent"), 1);
        EXPECT_EQ(statistic(source, "released"), 1);
    }
}

TEST(GarbagePlugin, MatcherRewritingTheDisparityDescriptionIsRefused) {
    const cv::Mat left(8, 16, CV_8UC1, cv::Scalar(1)), right(8, 16, CV_8UC1, cv::Scalar(1));
    for (const std::string defect : {"own_buffer", "shrink"}) {
        SCOPED_TRACE(defect);
        Matcher matcher = makeInstance<Matcher>("garbage_matcher", BINOCLE_KIND_MATCHER, "{defect: " + defect + "}");
        EXPECT_THAT(pluginErrorOf([&] { matcher.compute(left, right); }),
                    HasSubstr("compute failed (BINOCLE_ERR_INTERNAL): changed the host's disparity image description"));
    }
}

// A cloud of n points, i at (i, 2i, 1000 + i) mm, pixel index i.
struct TestCloud {
    explicit TestCloud(int64_t n) : xyz(3 * n), rgb(3 * n, 7), pixel(n) {
        for (int64_t i = 0; i < n; ++i) {
            xyz[3 * i] = static_cast<float>(i);
            xyz[3 * i + 1] = static_cast<float>(2 * i);
            xyz[3 * i + 2] = static_cast<float>(1000 + i);
            pixel[i] = static_cast<int32_t>(i);
        }
        view.count = n;
        view.xyz = xyz.data();
        view.rgb = rgb.data();
        view.pixel = pixel.data();
        view.image_width = 10;
        view.image_height = 10;
        view.frame = BINOCLE_FRAME_CAMERA;
    }
    std::vector<float> xyz;
    std::vector<uint8_t> rgb;
    std::vector<int32_t> pixel;
    binocle_cloud view{};
};

TEST(GarbagePlugin, TransformRaisingCountOrChangingFrameIsRefused) {
    for (const std::string defect : {"raise_count", "unknown_frame"}) {
        SCOPED_TRACE(defect);
        CloudTransform transform =
            makeInstance<CloudTransform>("garbage_transform", BINOCLE_KIND_CLOUD_TRANSFORM, "{defect: " + defect + "}");
        TestCloud cloud(5);
        EXPECT_THAT(pluginErrorOf([&] { transform.apply(cloud.view); }),
                    HasSubstr("apply failed (BINOCLE_ERR_INTERNAL): returned a garbage cloud"));
        EXPECT_EQ(cloud.view.count, 5); // the host's description is restored
        EXPECT_EQ(cloud.view.frame, BINOCLE_FRAME_CAMERA);
    }
}

// ---- The mocks do what their descriptions say ----------------------------------------------------

TEST(MockPlugins, MatcherWritesConstantOrShiftedDisparity) {
    const cv::Mat left(6, 12, CV_8UC1, cv::Scalar(1)), right = left.clone();
    Matcher constant = makeInstance<Matcher>("mock_matcher", BINOCLE_KIND_MATCHER, "{disparity_px: 2.5}");
    cv::Mat d = constant.compute(left, right);
    ASSERT_EQ(d.type(), CV_32F);
    EXPECT_EQ(cv::countNonZero(d != 2.5f), 0);
    EXPECT_EQ(constant.disparityRange(), std::make_pair(0, 16));

    Matcher shift = makeInstance<Matcher>("mock_matcher", BINOCLE_KIND_MATCHER, "{mode: shift, disparity_px: 3}");
    d = shift.compute(left, right);
    EXPECT_EQ(cv::countNonZero(d.colRange(0, 3) != BINOCLE_INVALID_DISPARITY), 0);
    EXPECT_EQ(cv::countNonZero(d.colRange(3, 12) != 3.0f), 0);
}

TEST(MockPlugins, PureCMatcherWorksThroughTheHost) {
    // Wider than 12.5 px: a larger disparity than the image width is made invalid.
    const cv::Mat left(5, 20, CV_8UC3, cv::Scalar(1, 2, 3)), right = left.clone();
    Matcher byDefault = makeInstance<Matcher>("c_matcher", BINOCLE_KIND_MATCHER);
    EXPECT_EQ(cv::countNonZero(byDefault.compute(left, right) != 8.0f), 0);
    Matcher set = makeInstance<Matcher>("c_matcher", BINOCLE_KIND_MATCHER, "{disparity_px: 12.5}");
    EXPECT_EQ(cv::countNonZero(set.compute(left, right) != 12.5f), 0);
    EXPECT_EQ(set.disparityRange(), std::make_pair(0, 13));
}

TEST(MockPlugins, TransformThinsAndShiftsTheCloud) {
    CloudTransform transform =
        makeInstance<CloudTransform>("mock_transform", BINOCLE_KIND_CLOUD_TRANSFORM, "{offset_z_mm: 5, keep_every: 3}");
    TestCloud cloud(10);
    transform.apply(cloud.view);
    ASSERT_EQ(cloud.view.count, 4); // points 0, 3, 6, 9
    for (int64_t k = 0; k < 4; ++k) {
        EXPECT_EQ(cloud.pixel[k], 3 * k);
        EXPECT_FLOAT_EQ(cloud.xyz[3 * k], 3.0f * k);
        EXPECT_FLOAT_EQ(cloud.xyz[3 * k + 2], 1000.0f + 3 * k + 5);
    }
}

TEST(MockPlugins, EvaluatorReportsThroughTheSink) {
    std::map<std::string, double> metrics;
    std::map<std::string, std::string> texts, units;
    HostSink sink;
    sink.metric = [&](const std::string &name, double value, const std::string &unit) {
        metrics[name] = value;
        units[name] = unit;
    };
    sink.text = [&](const std::string &name, const std::string &text) { texts[name] = text; };
    const PluginRecord &record = fixture("mock_evaluator", BINOCLE_KIND_EVALUATOR);
    Evaluator evaluator(record, paramsFromYaml(record), sink);

    cv::Mat disparity(4, 10, CV_32F, cv::Scalar(BINOCLE_INVALID_DISPARITY));
    disparity.colRange(0, 5).setTo(2.0f);
    binocle_image d{disparity.cols, disparity.rows, static_cast<int32_t>(disparity.step[0]), BINOCLE_PIXEL_FLOAT32, disparity.data};
    TestCloud cloud(7);
    binocle_stereo_frame frame{};
    frame.sequence = 41;
    binocle_eval_input in{};
    in.struct_size = sizeof(in);
    in.frame = &frame;
    in.disparity = &d;
    in.cloud = &cloud.view;
    evaluator.evaluate(in);
    EXPECT_EQ(metrics["frames_seen"], 1);
    EXPECT_EQ(metrics["valid_disparity_percent"], 50);
    EXPECT_EQ(units["valid_disparity_percent"], "%");
    EXPECT_EQ(metrics["cloud_points"], 7);
    EXPECT_EQ(texts["sequence"], "41");
    evaluator.evaluate(in);
    evaluator.finish();
    EXPECT_EQ(metrics["frames_total"], 2);
}

} // namespace
} // namespace binocle::test
