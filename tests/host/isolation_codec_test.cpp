// SPDX-License-Identifier: MIT
// Every message of the isolation codec survives a round trip (encode, then decode gives
// the same values and pixels), and a truncated or out-of-region message is refused.
#include "host/ipc_messages.hpp"
#include "host/ipc_planes.hpp"
#include "host/ipc_wire.hpp"
#include "host/kind_evaluator_messages.hpp"
#include "host/kind_matcher_messages.hpp"
#include "host/kind_source_messages.hpp"
#include "host/kind_transform_messages.hpp"
#include "host/plugin_kinds.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numeric>

namespace binocle::test {
namespace {

using ::testing::HasSubstr;

// A shared region as both ends see it: the writer's Layout copied into it.
struct Shared {
    std::vector<uint8_t> bytes;
    wire::Region fill(const wire::Layout &layout) {
        bytes.assign(layout.bytes() + 1, 0xAB);
        layout.copyInto(bytes.data());
        return {bytes.data(), bytes.size()};
    }
};

std::vector<uint8_t> pixels(const binocle_image &im) {
    const size_t row = static_cast<size_t>(im.width) * bytesPerPixel(im.format);
    std::vector<uint8_t> out;
    for (int32_t y = 0; y < im.height; ++y) {
        const auto *p = static_cast<const uint8_t *>(im.data) + static_cast<size_t>(y) * im.stride_bytes;
        out.insert(out.end(), p, p + row);
    }
    return out;
}

// A GRAY8 image with a stride wider than its rows, as a camera's buffer may be.
struct StridedImage {
    std::vector<uint8_t> data;
    binocle_image image{};
    StridedImage(int w, int h, int stride, uint8_t seed) : data(static_cast<size_t>(stride) * h) {
        std::iota(data.begin(), data.end(), seed);
        image = {w, h, stride, BINOCLE_PIXEL_GRAY8, data.data()};
    }
};

TEST(IsolationCodec, RequestHeadRoundTrips) {
    wire::Writer w;
    wire::put(w, wire::RequestHead{42, 7, 1u << 20});
    w.put<int32_t>(-5);
    wire::Reader r(w.data());
    const wire::RequestHead h = wire::get<wire::RequestHead>(r);
    EXPECT_EQ(h.op, 42u);
    EXPECT_EQ(h.region, 7u);
    EXPECT_EQ(h.region_bytes, 1u << 20);
    EXPECT_EQ(r.get<int32_t>(), -5); // the operation's own fields follow the head
    wire::Writer none;
    wire::put(none, wire::RequestHead{});
    wire::Reader rn(none.data());
    EXPECT_EQ(wire::get<wire::RequestHead>(rn).region, wire::kNoRegion);
}

TEST(IsolationCodec, CreateCarriesTheKindAndEverySettingType) {
    ParamValues p;
    p.setBool("flag", true);
    p.setInt("window_px", -7, false);
    p.setDouble("scale", 0.25);
    p.setText("mode", BINOCLE_PARAM_ENUM, "shift");
    p.setText("empty", BINOCLE_PARAM_STRING, "");
    wire::Writer w;
    wire::putCreate(w, BINOCLE_KIND_MATCHER, p);
    wire::Reader r(w.data());
    auto [kind, q] = wire::getCreate(r);
    EXPECT_EQ(kind, BINOCLE_KIND_MATCHER);
    ASSERT_EQ(q.size(), 5);
    EXPECT_EQ(q.find("flag")->i, 1);
    EXPECT_EQ(q.find("window_px")->i, -7);
    EXPECT_FALSE(q.find("window_px")->explicit_);
    EXPECT_EQ(q.find("scale")->d, 0.25);
    EXPECT_STREQ(q.find("mode")->s, "shift");
    EXPECT_EQ(q.find("mode")->type, BINOCLE_PARAM_ENUM);
    ASSERT_NE(q.find("empty")->s, nullptr); // "" stays "", not NULL
    EXPECT_STREQ(q.find("empty")->s, "");
    EXPECT_TRUE(r.atEnd());
}

TEST(IsolationCodec, LogMetricTextAndReplyRoundTrip) {
    {
        wire::Reader r(wire::encode(wire::LogMessage{wire::kFromOutput, BINOCLE_LOG_WARNING, "a line"}));
        EXPECT_EQ(r.get<uint32_t>(), wire::kLog);
        const auto m = wire::get<wire::LogMessage>(r);
        EXPECT_EQ(m.origin, wire::kFromOutput);
        EXPECT_EQ(m.level, BINOCLE_LOG_WARNING);
        EXPECT_EQ(m.text, "a line");
    }
    {
        wire::Reader r(wire::encode(wire::MetricMessage{"bad_px", 12.5, "%"}));
        EXPECT_EQ(r.get<uint32_t>(), wire::kMetric);
        const auto m = wire::get<wire::MetricMessage>(r);
        EXPECT_EQ(m.name, "bad_px");
        EXPECT_EQ(m.value, 12.5);
        EXPECT_EQ(m.unit, "%");
    }
    {
        wire::Reader r(wire::encode(wire::TextMessage{"objects", "- {id: 1}\n"}));
        EXPECT_EQ(r.get<uint32_t>(), wire::kText);
        const auto m = wire::get<wire::TextMessage>(r);
        EXPECT_EQ(m.name, "objects");
        EXPECT_EQ(m.text, "- {id: 1}\n");
    }
    {
        wire::Writer payload;
        wire::putRange(payload, {-3, 64});
        wire::Reader r(wire::encodeReply(BINOCLE_ERR_BUSY, "all frames lent", payload.data()));
        EXPECT_EQ(r.get<uint32_t>(), wire::kReply);
        const auto h = wire::get<wire::ReplyHead>(r);
        EXPECT_EQ(h.rc, BINOCLE_ERR_BUSY);
        EXPECT_EQ(h.message, "all frames lent");
        EXPECT_EQ(wire::getRange(r), std::make_pair(-3, 64));
    }
}

TEST(IsolationCodec, DescriptionOfEveryKindRoundTrips) {
    binocle_param_desc params[2] = {};
    params[0].name = "window_px";
    params[0].type = BINOCLE_PARAM_INT;
    params[0].flags = BINOCLE_PARAM_FLAG_HAS_MIN | BINOCLE_PARAM_FLAG_ODD;
    params[0].default_value = "5";
    params[0].min = 3;
    params[0].multiple_of = 0;
    params[0].help = "window";
    params[1].name = "mode";
    params[1].type = BINOCLE_PARAM_ENUM;
    params[1].flags = BINOCLE_PARAM_FLAG_REQUIRED;
    params[1].choices = "a|b";
    params[1].unit = nullptr; // NULL stays NULL
    for (const PluginKind *kind : pluginKinds()) {
        binocle_plugin_header h{};
        h.struct_size = static_cast<uint32_t>(kind->tableSize);
        h.abi_version = BINOCLE_ABI_VERSION;
        h.api_version = 1;
        h.kind = kind->kind;
        h.name = "thing";
        h.version = "1.2";
        h.description = nullptr;
        wire::Writer w;
        wire::putDescription(w, h, {params[0], params[1]});
        wire::Reader r(w.data());
        const PluginRecord rec = wire::getDescription(r, "/x/binocle_thing.so");
        EXPECT_TRUE(rec.described);
        EXPECT_EQ(rec.kind, kind->kind) << kind->name;
        EXPECT_EQ(rec.name, "thing");
        EXPECT_EQ(rec.version, "1.2");
        EXPECT_EQ(rec.table->description, nullptr);
        EXPECT_EQ(rec.table->struct_size, kind->tableSize);
        const auto got = rec.params();
        ASSERT_EQ(got.size(), 2u) << kind->name;
        EXPECT_STREQ(got[0].name, "window_px");
        EXPECT_EQ(got[0].flags, params[0].flags);
        EXPECT_STREQ(got[0].default_value, "5");
        EXPECT_EQ(got[0].min, 3);
        EXPECT_STREQ(got[0].help, "window");
        EXPECT_STREQ(got[1].choices, "a|b");
        EXPECT_EQ(got[1].default_value, nullptr);
        EXPECT_EQ(got[1].unit, nullptr);
        EXPECT_EQ(kind->missingEntries(rec.table).size(), 3u + (kind->kind == BINOCLE_KIND_STEREO_SOURCE ? 2u : 1u))
            << "a description has no entry points";
    }
}

TEST(IsolationCodec, FrameRoundTripsWithItsPlanesInTheRegion) {
    StridedImage left(5, 3, 8, 1), right(5, 3, 8, 100), gt(2, 2, 2, 50);
    binocle_named_image extra{"gt_valid", gt.image};
    binocle_stereo_frame f{};
    f.struct_size = sizeof f;
    f.sequence = 9;
    f.timestamp_left_ns = -1;
    f.timestamp_right_ns = 123456789012345;
    f.left = left.image;
    f.right = right.image;
    f.extras = &extra;
    f.extra_count = 1;
    f.metadata = "objects: []";
    wire::Layout layout;
    wire::Writer w;
    wire::putFrame(w, layout, f);
    Shared shared;
    const wire::Region region = shared.fill(layout);
    wire::Reader r(w.data());
    wire::FrameTexts texts;
    const binocle_stereo_frame g = wire::getFrame(r, region, texts);
    EXPECT_EQ(g.sequence, 9u);
    EXPECT_EQ(g.timestamp_left_ns, -1);
    EXPECT_EQ(g.timestamp_right_ns, 123456789012345);
    EXPECT_EQ(g.left.stride_bytes, 5); // tightly packed in the region
    EXPECT_EQ(pixels(g.left), pixels(f.left));
    EXPECT_EQ(pixels(g.right), pixels(f.right));
    ASSERT_EQ(g.extra_count, 1);
    EXPECT_STREQ(g.extras[0].name, "gt_valid");
    EXPECT_EQ(pixels(g.extras[0].image), pixels(gt.image));
    EXPECT_STREQ(g.metadata, "objects: []");

    f.metadata = nullptr; // NULL metadata stays NULL
    f.extra_count = 0;
    f.extras = nullptr;
    wire::Layout l2;
    wire::Writer w2;
    wire::putFrame(w2, l2, f);
    Shared s2;
    wire::Reader r2(w2.data());
    const binocle_stereo_frame g2 = wire::getFrame(r2, s2.fill(l2), texts);
    EXPECT_EQ(g2.metadata, nullptr);
    EXPECT_EQ(g2.extras, nullptr);
}

TEST(IsolationCodec, AnImagePlacedTwiceIsCopiedOnce) {
    StridedImage im(4, 4, 4, 7);
    wire::Layout layout;
    const binocle_image a = layout.place(im.image), b = layout.place(im.image);
    EXPECT_EQ(a.data, b.data);
    EXPECT_EQ(layout.bytes(), 16u);
}

TEST(IsolationCodec, CloudRoundTripsWithAndWithoutItsOptionalArrays) {
    std::vector<float> xyz = {1, 2, 3, 4, 5, 6};
    std::vector<uint8_t> rgb = {10, 20, 30, 40, 50, 60};
    std::vector<int32_t> pixel = {7, 8};
    binocle_cloud c{};
    c.count = 2;
    c.xyz = xyz.data();
    c.rgb = rgb.data();
    c.pixel = pixel.data();
    c.image_width = 4;
    c.image_height = 2;
    c.frame = BINOCLE_FRAME_GROUND;
    for (bool optional : {true, false}) {
        if (!optional) c.rgb = nullptr, c.pixel = nullptr;
        wire::Layout layout;
        wire::Writer w;
        wire::putCloud(w, layout, c);
        Shared shared;
        wire::Reader r(w.data());
        const binocle_cloud d = wire::getCloud(r, shared.fill(layout));
        EXPECT_EQ(d.count, 2);
        EXPECT_EQ(d.image_width, 4);
        EXPECT_EQ(d.image_height, 2);
        EXPECT_EQ(d.frame, BINOCLE_FRAME_GROUND);
        EXPECT_EQ(std::vector<float>(d.xyz, d.xyz + 6), xyz);
        if (optional) {
            EXPECT_EQ(std::vector<uint8_t>(d.rgb, d.rgb + 6), rgb);
            EXPECT_EQ(std::vector<int32_t>(d.pixel, d.pixel + 2), pixel);
        } else {
            EXPECT_EQ(d.rgb, nullptr);
            EXPECT_EQ(d.pixel, nullptr);
        }
    }
}

TEST(IsolationCodec, TheKindsCallsRoundTrip) {
    wire::Writer w;
    wire::put(w, wire::ComputeRequest{640, 480, 16, 4096 * 80, 4096 * 600});
    wire::putGrabRequest(w, -1);
    wire::put(w, wire::AppliedCloud{12, BINOCLE_FRAME_CAMERA, 64, 0, 192});
    wire::Reader r(w.data());
    const auto c = wire::get<wire::ComputeRequest>(r);
    EXPECT_EQ(c.width, 640);
    EXPECT_EQ(c.height, 480);
    EXPECT_EQ(c.cv_type, 16);
    EXPECT_EQ(c.image_bytes, 4096u * 80);
    EXPECT_EQ(c.extras_bytes, 4096u * 600);
    EXPECT_EQ(wire::getGrabRequest(r), -1);
    const auto a = wire::get<wire::AppliedCloud>(r);
    EXPECT_EQ(a.count, 12);
    EXPECT_EQ(a.frame, BINOCLE_FRAME_CAMERA);
    EXPECT_EQ(a.xyz, 64u);
    EXPECT_EQ(a.rgb, 0u);
    EXPECT_EQ(a.pixel, 192u);
    EXPECT_TRUE(r.atEnd());
}

TEST(IsolationCodec, EvaluateRoundTripsAndKeepsTextsNotSentAgain) {
    StridedImage left(4, 2, 4, 1), disparity(4, 2, 4, 9);
    binocle_image d = disparity.image;
    binocle_stereo_frame f{};
    f.struct_size = sizeof f;
    f.left = f.right = left.image;
    binocle_eval_input in{};
    in.struct_size = sizeof in;
    in.frame = &f;
    in.rectified_left = &f.left;
    in.disparity = &d;
    in.calibration_yaml = "K: [1]";
    in.rig_yaml = nullptr;
    in.output_dir = "/tmp/out";
    in.min_disparity = -3;
    in.num_disparities = 96;
    in.ground_pose_known = 1;
    in.camera_height_mm = 1234.5;
    in.inclination_deg = 7.25;
    StridedImage filled(4, 2, 6, 255);
    const binocle_named_image extras[] = {{"disparity_filled", filled.image}};
    in.disparity_extras = extras;
    in.disparity_extra_count = 1;
    wire::EvaluateTexts kept;
    for (bool send : {true, false}) {
        wire::Layout layout;
        wire::Writer w;
        wire::putEvaluate(w, layout, in, send, send);
        Shared shared;
        wire::Reader r(w.data());
        wire::EvaluateInput got;
        wire::getEvaluate(r, shared.fill(layout), kept, got);
        ASSERT_NE(got.in.frame, nullptr);
        EXPECT_EQ(pixels(got.in.frame->left), pixels(f.left));
        ASSERT_NE(got.in.rectified_left, nullptr);
        EXPECT_EQ(got.in.rectified_right, nullptr);
        ASSERT_NE(got.in.disparity, nullptr);
        EXPECT_EQ(pixels(*got.in.disparity), pixels(d));
        EXPECT_EQ(got.in.cloud, nullptr);
        EXPECT_STREQ(got.in.calibration_yaml, "K: [1]") << "sent: " << send; // kept from the first
        EXPECT_EQ(got.in.rig_yaml, nullptr);
        EXPECT_STREQ(got.in.output_dir, "/tmp/out");
        EXPECT_EQ(got.in.min_disparity, -3);
        EXPECT_EQ(got.in.num_disparities, 96);
        EXPECT_EQ(got.in.ground_pose_known, 1);
        EXPECT_EQ(got.in.camera_height_mm, 1234.5);
        EXPECT_EQ(got.in.inclination_deg, 7.25);
        ASSERT_EQ(got.in.disparity_extra_count, 1);
        EXPECT_STREQ(got.in.disparity_extras[0].name, "disparity_filled");
        EXPECT_EQ(pixels(got.in.disparity_extras[0].image), pixels(filled.image));
        EXPECT_TRUE(r.atEnd());
    }
}

TEST(IsolationCodec, TruncatedMessagesAndPlanesOutsideTheRegionAreRefused) {
    wire::Writer w;
    wire::put(w, wire::ComputeRequest{1, 2, 3, 4});
    const std::string cut = w.data().substr(0, w.data().size() - 1);
    wire::Reader r(cut);
    EXPECT_THROW(wire::get<wire::ComputeRequest>(r), Error);

    StridedImage im(4, 4, 4, 0);
    wire::Layout layout;
    wire::Writer wi;
    wire::putImage(wi, layout.place(im.image));
    std::vector<uint8_t> small(8);
    wire::Reader ri(wi.data());
    try {
        wire::getImage(ri, {small.data(), small.size()});
        ADD_FAILURE() << "an image larger than the region was accepted";
    } catch (const Error &e) {
        EXPECT_THAT(e.what(), HasSubstr("outside the shared memory"));
    }
}

} // namespace
} // namespace binocle::test
