// SPDX-License-Identifier: MIT
// ABI evolution seen from today's host: a plugin built against the frozen API-1 headers
// and one built against the next API (an entry appended) both load and work; the least
// table sizes are frozen per kind and API version.
#include "host/fixture_host.hpp"

#include <opencv2/core.hpp>

namespace binocle::test {
namespace {

using ::testing::HasSubstr;

TEST(AbiEvolution, LeastTableSizesAreTheEndOfTheLastApi1Entry) {
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_MATCHER, 1), offsetof(binocle_matcher_api, disparity_range) + sizeof(void *));
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_STEREO_SOURCE, 1), offsetof(binocle_source_api, enumerate_devices) + sizeof(void *));
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_CLOUD_TRANSFORM, 1), offsetof(binocle_cloud_transform_api, apply) + sizeof(void *));
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_EVALUATOR, 1), offsetof(binocle_evaluator_api, finish) + sizeof(void *));
#if UINTPTR_MAX == 0xffffffffffffffffu
    // The numbers of the API-1 tables on LP64, as the frozen headers laid them out; a
    // change here breaks every plugin already built.
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_MATCHER, 1), 96u);
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_STEREO_SOURCE, 1), 136u);
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_CLOUD_TRANSFORM, 1), 88u);
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_EVALUATOR, 1), 96u);
#endif
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_MATCHER, 99), 0u);
    EXPECT_EQ(leastTableSize(42, 1), 0u);
}

TEST(AbiEvolution, FrozenApi1MatcherLoadsAndComputes) {
    const PluginRecord &r = fixture("frozen_matcher", BINOCLE_KIND_MATCHER);
    EXPECT_EQ(r.api_version, 1u);
    EXPECT_EQ(r.table->struct_size, leastTableSize(BINOCLE_KIND_MATCHER, 1));
    Matcher m(r, paramsFromYaml(r, "{disparity_px: 5}"));
    cv::Mat left(24, 32, CV_8UC1, cv::Scalar(9)), right = left.clone();
    cv::Mat d = m.compute(left, right);
    EXPECT_EQ(cv::countNonZero(d == 5.0f), 32 * 24);
    EXPECT_EQ(m.disparityRange(), (std::pair<int32_t, int32_t>{0, 8}));
    // Its table ends before `extras` (appended after API 1): the host's copy reads it as
    // absent and the disparity comes without extra planes.
    EXPECT_LT(r.table->struct_size, offsetof(binocle_matcher_api, extras) + sizeof(void *));
    EXPECT_EQ(reinterpret_cast<const binocle_matcher_api *>(r.table)->extras, nullptr);
    EXPECT_TRUE(m.extras().empty());
}

TEST(AbiEvolution, FrozenApi1SourceLendsFramesUntilTheEnd) {
    const PluginRecord &r = fixture("frozen_source", BINOCLE_KIND_STEREO_SOURCE);
    EXPECT_EQ(r.table->struct_size, leastTableSize(BINOCLE_KIND_STEREO_SOURCE, 1));
    Source s(r, paramsFromYaml(r, "{frames: 2}"));
    s.start();
    auto a = s.grab();
    auto b = s.grab();
    ASSERT_TRUE(a && b);
    EXPECT_EQ(b->raw().sequence, 1u);
    EXPECT_EQ(b->left().at<uint8_t>(0, 0), 10);
    EXPECT_EQ(s.grab(), nullptr); // END_OF_STREAM
}

TEST(AbiEvolution, Api2PluginWithAnAppendedEntryLoadsInThisHost) {
    const PluginRecord &r = fixture("future_matcher", BINOCLE_KIND_MATCHER);
    EXPECT_EQ(r.api_version, 2u);
    EXPECT_GT(r.api_version, BINOCLE_API_VERSION);
    // The plugin's table is one entry longer than the host's; the host copied only what
    // it knows.
    EXPECT_EQ(r.table->struct_size, sizeof(binocle_matcher_api) + sizeof(void *));
    Matcher m(r, paramsFromYaml(r));
    cv::Mat left(10, 20, CV_8UC3, cv::Scalar(1, 2, 3));
    EXPECT_EQ(cv::countNonZero(m.compute(left, left) == 3.0f), 200);
    EXPECT_EQ(m.disparityRange(), (std::pair<int32_t, int32_t>{0, 4}));
}

TEST(AbiEvolution, EntriesPastStructSizeReadAsAbsent) {
    // A plugin that declares only the header and the first fields of a matcher table
    // (struct_size below API 1's) is refused; one of exactly API 1's size is accepted and
    // the host's copy holds zeros past it (checked in abi_future_host_test with a longer
    // table). Here: the least API-1 size is what the frozen plugin declared.
    EXPECT_THAT(refusalOf("short_table"), HasSubstr("smaller than the source table of ABI 1 API 1"));
}

} // namespace
} // namespace binocle::test
