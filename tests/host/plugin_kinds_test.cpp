// SPDX-License-Identifier: MIT
// The plugin kinds' descriptors: one per kind of the ABI, each with the name, rig key,
// least table size and mandatory entries that loading and the helper process read.
#include "host/child_process.hpp"
#include "host/plugin_kinds.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <csignal>
#include <set>
#include <sys/wait.h>
#include <thread>

namespace binocle::test {
namespace {

using ::testing::ElementsAre;

TEST(PluginKinds, OneDescriptorPerKindOfTheAbi) {
    std::vector<std::string> names, keys;
    for (const PluginKind *k : pluginKinds()) {
        names.emplace_back(k->name);
        keys.emplace_back(k->rigKey);
        EXPECT_EQ(pluginKind(k->kind), k);
        EXPECT_STREQ(kindName(k->kind), k->name);
        EXPECT_NE(k->serve, nullptr) << k->name << " has no isolated side";
        EXPECT_GE(k->tableSize, k->leastTableSize(1)) << k->name;
    }
    EXPECT_THAT(names, ElementsAre("source", "matcher", "transform", "evaluator"));
    EXPECT_THAT(keys, ElementsAre("source", "matcher", "transforms", "evaluators"));
    EXPECT_EQ(pluginKindNamed("transform"), pluginKind(BINOCLE_KIND_CLOUD_TRANSFORM));
    EXPECT_EQ(pluginKindNamed("transforms"), nullptr);
    EXPECT_EQ(requireKind(BINOCLE_KIND_STEREO_SOURCE).inRig, PluginKind::InRig::One);
    EXPECT_EQ(requireKind(BINOCLE_KIND_MATCHER).inRig, PluginKind::InRig::One);
    EXPECT_EQ(requireKind(BINOCLE_KIND_CLOUD_TRANSFORM).inRig, PluginKind::InRig::List);
    EXPECT_EQ(requireKind(BINOCLE_KIND_EVALUATOR).inRig, PluginKind::InRig::List);
    EXPECT_EQ(pluginKind(99), nullptr);
    EXPECT_STREQ(kindName(99), "unknown");
    EXPECT_EQ(leastTableSize(99, 1), 0u);
    EXPECT_THROW(requireKind(99), Error);
}

TEST(PluginKinds, ApiOneTablesEndAtTheirLastEntry) {
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_MATCHER, 1), BINOCLE_END_OF(binocle_matcher_api, disparity_range));
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_STEREO_SOURCE, 1), BINOCLE_END_OF(binocle_source_api, enumerate_devices));
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_CLOUD_TRANSFORM, 1), BINOCLE_END_OF(binocle_cloud_transform_api, apply));
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_EVALUATOR, 1), BINOCLE_END_OF(binocle_evaluator_api, finish));
    EXPECT_EQ(leastTableSize(BINOCLE_KIND_MATCHER, 0), 0u);
}

TEST(PluginKinds, MandatoryEntriesLeftNullAreNamed) {
    binocle_matcher_api t{};
    t.header.kind = BINOCLE_KIND_MATCHER;
    const PluginKind &k = requireKind(BINOCLE_KIND_MATCHER);
    EXPECT_THAT(k.missingEntries(&t.header), ElementsAre("create", "destroy", "last_error", "compute"));
    t.compute = [](binocle_matcher *, const binocle_image *, const binocle_image *, binocle_image *) -> binocle_result {
        return BINOCLE_OK;
    };
    EXPECT_THAT(k.missingEntries(&t.header), ElementsAre("create", "destroy", "last_error"));
    binocle_param_desc d{};
    d.name = "x";
    k.setParams(&t.header, &d, 1);
    EXPECT_EQ(t.params, &d);
    EXPECT_EQ(t.param_count, 1);
    ASSERT_EQ(k.params(&t.header).size(), 1u);
}

TEST(PluginKinds, EveryIsolatedCallHasItsEntrysName) {
    for (const PluginKind *k : pluginKinds()) {
        std::set<uint32_t> ops;
        for (const auto &e : k->entries) {
            if (!e.op) continue;
            EXPECT_TRUE(ops.insert(e.op).second) << k->name << ": two entries share request " << e.op;
            EXPECT_STREQ(k->callName(e.op), e.name);
        }
        EXPECT_FALSE(ops.empty()) << k->name;
    }
}

TEST(DeadlineChild, ReturnsWhatTheChildSaid) {
    const auto end = DeadlineChild::run([] { return std::string("fine"); }, 5000);
    EXPECT_FALSE(end.timedOut);
    EXPECT_TRUE(WIFEXITED(end.status));
    EXPECT_EQ(end.output, "fine");
}

TEST(DeadlineChild, ACrashIsTheSignal) {
    const auto end = DeadlineChild::run(
        [] {
            std::raise(SIGSEGV);
            return std::string("unreachable");
        },
        5000);
    EXPECT_FALSE(end.timedOut);
    EXPECT_EQ(describeExit(end.status), "killed by signal 11 (SIGSEGV)");
    EXPECT_EQ(end.output, "");
}

TEST(DeadlineChild, AHangIsKilledAtItsDeadline) {
    const auto end = DeadlineChild::run(
        [] {
            std::this_thread::sleep_for(std::chrono::seconds(30));
            return std::string("late");
        },
        200);
    EXPECT_TRUE(end.timedOut);
    EXPECT_EQ(describeExit(end.status), "killed by signal 9 (SIGKILL)");
    EXPECT_LT(end.seconds, 10);
}

} // namespace
} // namespace binocle::test
