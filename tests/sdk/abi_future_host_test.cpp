// SPDX-License-Identifier: MIT
// A host of the next API: framework/host compiled against tests/sdk/frozen/api2_future,
// where the matcher table has one more entry (describe). It must load today's API-1
// plugins, with that entry read as absent, and use it where a plugin has it.
#include "host/plugin_host.hpp"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

static_assert(BINOCLE_API_VERSION == 2, "this test must be built against tests/sdk/frozen/api2_future");

namespace binocle {
namespace {

std::string fixturePath(const std::string &name) { return std::string(BINOCLE_TEST_PLUGIN_DIR) + "/binocle_" + name + ".so"; }

const binocle_matcher_api *matcherTable(const PluginRecord &r) { return reinterpret_cast<const binocle_matcher_api *>(r.table); }

TEST(FutureHost, LoadsAFrozenApi1PluginWithTheAppendedEntryAbsent) {
    PluginHost host(std::vector<std::string>{});
    const PluginRecord &r = host.load(fixturePath("frozen_matcher"));
    EXPECT_EQ(r.api_version, 1u);
    EXPECT_LT(r.table->struct_size, sizeof(binocle_matcher_api));
    EXPECT_EQ(matcherTable(r)->describe, nullptr); // past struct_size: absent, not garbage
    EXPECT_NE(matcherTable(r)->compute, nullptr);
    ParamValues values;
    values.setDouble("disparity_px", 6, false);
    Matcher m(r, values);
    cv::Mat left(8, 16, CV_8UC1, cv::Scalar(0));
    EXPECT_EQ(cv::countNonZero(m.compute(left, left) == 6.0f), 128);
}

TEST(FutureHost, LoadsTodaysPluginsBuiltWithTheCurrentSdk) {
    PluginHost host(std::vector<std::string>{});
    for (const char *name : {"mock_matcher", "c_matcher", "mock_source", "mock_transform", "mock_evaluator"}) {
        const PluginRecord &r = host.load(fixturePath(name));
        EXPECT_EQ(r.api_version, 1u) << name;
    }
    EXPECT_EQ(matcherTable(*host.find("mock_matcher"))->describe, nullptr);
}

TEST(FutureHost, UsesTheAppendedEntryOfAnApi2Plugin) {
    PluginHost host(std::vector<std::string>{});
    const PluginRecord &r = host.load(fixturePath("future_matcher"));
    EXPECT_EQ(r.api_version, 2u);
    EXPECT_EQ(r.table->struct_size, sizeof(binocle_matcher_api));
    ASSERT_NE(matcherTable(r)->describe, nullptr);
    binocle_matcher *handle = nullptr;
    ASSERT_EQ(matcherTable(r)->create(nullptr, 0, nullptr, &handle), BINOCLE_OK);
    const char *text = nullptr;
    EXPECT_EQ(matcherTable(r)->describe(handle, &text), BINOCLE_OK);
    EXPECT_STREQ(text, "constant 3 px");
    matcherTable(r)->destroy(handle);
}

} // namespace
} // namespace binocle
