// SPDX-License-Identifier: MIT
// The stage pipeline with the fixture plugins: frame order behind parallel matchers,
// the lossless and latest policies and their drop counts, frames.jsonl, a clean stop,
// a source outage ridden out with on_source_error: retry, and the pipeline's instances
// held by type.
#include "common/test_util.hpp"
#include "config/rig_config.hpp"
#include "files/atomic_file.hpp"
#include "core/error.hpp"
#include "pipeline/pipeline.hpp"
#include "pipeline/plugin_instances.hpp"
#include "pipeline/stage_times.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>
#include <yaml-cpp/yaml.h>

namespace binocle::test {
namespace {

using Json = nlohmann::ordered_json;

const PluginHost &host() {
    static const std::unique_ptr<PluginHost> h = [] {
        auto p = std::make_unique<PluginHost>(std::vector<std::string>{BINOCLE_TEST_PLUGIN_DIR});
        p->scan();
        return p;
    }();
    return *h;
}

RigConfig mockRig(const std::string &source, const std::string &runtime = "") {
    const std::string text = "name: mocks\nsource:\n  plugin: mock_source\n" + source +
                             "matcher:\n  plugin: mock_matcher\n  disparity_px: 4\n"
                             "evaluators:\n  - plugin: mock_evaluator\n"
                             "outputs: {disparity_png: false, disparity_color: false, cloud_ply: false}\n" +
                             (runtime.empty() ? "" : "runtime:\n" + runtime);
    return rigFromNode(YAML::Load(text), std::string(BINOCLE_SOURCE_DIR) + "/tests/pipeline/mocks.yaml", host());
}

std::vector<Json> readLines(const std::string &path) {
    std::vector<Json> lines;
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) lines.push_back(Json::parse(line));
    return lines;
}

YAML::Node statisticsOf(const Json &summary) { return YAML::Load(summary.at("source_statistics").get<std::string>()); }

bool anyTemporaryFile(const std::string &dir) {
    for (const auto &e : std::filesystem::directory_iterator(dir))
        if (e.path().filename().string().find(".tmp") != std::string::npos) return true;
    return false;
}

TEST(Pipeline, ParallelMatchersKeepFrameOrderAndEveryFrameIsReleased) {
    TempDir dir;
    Pipeline p(mockRig("  frames: 30\n", "  matcher_instances: 3\n"), host());
    RunOptions o;
    o.out_dir = dir.str("out");
    o.progress = false;
    std::vector<uint64_t> seen;
    const Json summary = p.run(o, [&](const FrameResult &r) {
        EXPECT_EQ(r.index, r.sequence);
        EXPECT_EQ(r.cloud.size(), 64u * 48u); // mock_matcher: d = 4 px everywhere
        seen.push_back(r.sequence);
    });
    std::vector<uint64_t> expected(30);
    for (uint64_t i = 0; i < 30; ++i) expected[i] = i;
    EXPECT_EQ(seen, expected);
    EXPECT_EQ(summary["status"], "ok");
    EXPECT_EQ(summary["frame_count"], 30);
    EXPECT_EQ(summary["runtime"]["policy"], "lossless");
    EXPECT_EQ(summary["runtime"]["policy_from"], "source (not live)");
    EXPECT_EQ(summary["dropped"]["total"], 0);
    EXPECT_EQ(summary["metrics"]["mock_evaluator"]["frames_total"], 30);
    const YAML::Node st = statisticsOf(summary);
    EXPECT_EQ(st["lent"].as<int>(), 30);
    EXPECT_EQ(st["released"].as<int>(), 30);
    // One line per frame, in order, with its figures; the summary keeps none of them.
    const std::vector<Json> lines = readLines(dir.str("out/frames.jsonl"));
    ASSERT_EQ(lines.size(), 30u);
    for (size_t i = 0; i < lines.size(); ++i) {
        EXPECT_EQ(lines[i]["sequence"], i);
        EXPECT_EQ(lines[i]["metrics"]["mock_evaluator"]["frames_seen"], i + 1);
    }
    EXPECT_FALSE(summary.contains("frames"));
    EXPECT_TRUE(std::filesystem::exists(dir.str("out/summary.json")));
}

TEST(Pipeline, LatestPolicyDropsTheOldestFramesOfALiveSourceAndCountsThem) {
    // A live camera at 500 fps and a consumer at 50 fps: the source never waits.
    Pipeline p(mockRig("  frames: 60\n  live: true\n  frame_interval_ms: 2\n", "  queue_depth: 2\n"), host());
    RunOptions o;
    o.progress = false;
    std::vector<uint64_t> seen;
    const Json summary = p.run(o, [&](const FrameResult &r) {
        seen.push_back(r.sequence);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    });
    EXPECT_EQ(summary["runtime"]["policy"], "latest");
    EXPECT_EQ(summary["runtime"]["policy_from"], "source (live)");
    EXPECT_EQ(summary["frames_grabbed"], 60);
    const int64_t dropped = summary["dropped"]["by_policy"];
    EXPECT_GT(dropped, 10);
    EXPECT_EQ(summary["frame_count"].get<int64_t>() + dropped, 60);
    EXPECT_EQ(static_cast<int64_t>(seen.size()), summary["frame_count"].get<int64_t>());
    for (size_t i = 1; i < seen.size(); ++i) EXPECT_LT(seen[i - 1], seen[i]);
    const YAML::Node st = statisticsOf(summary);
    EXPECT_EQ(st["lent"].as<int>(), st["released"].as<int>()); // dropped frames go back too
}

TEST(Pipeline, LosslessPolicyMakesEvenALiveSourceWait) {
    Pipeline p(mockRig("  frames: 20\n  live: true\n", "  policy: lossless\n  queue_depth: 1\n"), host());
    RunOptions o;
    o.progress = false;
    int64_t n = 0;
    const Json summary = p.run(o, [&](const FrameResult &) {
        ++n;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    });
    EXPECT_EQ(summary["runtime"]["policy_from"], "rig");
    EXPECT_EQ(n, 20);
    EXPECT_EQ(summary["dropped"]["by_policy"], 0);
}

TEST(Pipeline, StopRequestFinishesTheFramesInFlightAndSaysInterrupted) {
    TempDir dir;
    Pipeline p(mockRig("  frames: 1000000\n"), host());
    std::atomic<bool> stop{false};
    RunOptions o;
    o.out_dir = dir.str("out");
    o.progress = false;
    o.stop = &stop;
    int64_t n = 0;
    const Json summary = p.run(o, [&](const FrameResult &) {
        if (++n == 5) stop = true;
    });
    EXPECT_EQ(summary["status"], "interrupted");
    EXPECT_GE(n, 5);
    EXPECT_LT(n, 100); // only what was in flight
    EXPECT_EQ(summary["frame_count"], n);
    EXPECT_EQ(summary["frames_grabbed"], n); // lossless: every grabbed frame finished
    EXPECT_EQ(static_cast<int64_t>(readLines(dir.str("out/frames.jsonl")).size()), n);
    const Json written = Json::parse(readTextFile(dir.str("out/summary.json")));
    EXPECT_EQ(written["status"], "interrupted");
    EXPECT_FALSE(anyTemporaryFile(dir.str("out")));
    const YAML::Node st = statisticsOf(summary);
    EXPECT_EQ(st["lent"].as<int>(), st["released"].as<int>());
}

TEST(Pipeline, RetryRidesOutASourceOutage) {
    for (const char *code : {"device", "timeout"}) {
        SCOPED_TRACE(code);
        TempDir dir;
        Pipeline p(mockRig("  frames: 12\n  fail_after: 5\n  fail_for_ms: 600\n  fail_code: " + std::string(code) + "\n",
                           "  on_source_error: retry\n  retry_for_s: 10\n"),
                   host());
        RunOptions o;
        o.out_dir = dir.str("out");
        o.progress = false;
        o.grab_timeout_ms = 200;
        const Json summary = p.run(o);
        EXPECT_EQ(summary["status"], "ok");
        EXPECT_EQ(summary["frame_count"], 12);
        EXPECT_EQ(summary["source_errors"]["outages"], 1);
        EXPECT_EQ(summary["source_errors"]["recovered"], 1);
        EXPECT_NE(summary["source_errors"]["last"].get<std::string>().find("camera gone"), std::string::npos);
        EXPECT_GT(statisticsOf(summary)["failed_grabs"].as<int>(), 0);
        // Frames from before and after the outage.
        const std::vector<Json> lines = readLines(dir.str("out/frames.jsonl"));
        ASSERT_EQ(lines.size(), 12u);
        EXPECT_EQ(lines[4]["sequence"], 4);
        EXPECT_EQ(lines[5]["sequence"], 5);
        EXPECT_EQ(lines[11]["sequence"], 11);
    }
}

TEST(Pipeline, OutageLongerThanRetryForFailsAndKeepsTheFramesBefore) {
    TempDir dir;
    Pipeline p(mockRig("  frames: 12\n  fail_after: 5\n  fail_for_ms: 5000\n", "  on_source_error: retry\n  retry_for_s: 0.3\n"),
               host());
    RunOptions o;
    o.out_dir = dir.str("out");
    o.progress = false;
    try {
        p.run(o);
        FAIL() << "the run should fail";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("still failing after retry_for_s"), std::string::npos) << e.what();
    }
    const Json summary = Json::parse(readTextFile(dir.str("out/summary.json")));
    EXPECT_EQ(summary["status"], "failed");
    EXPECT_EQ(summary["frame_count"], 5);
    EXPECT_EQ(readLines(dir.str("out/frames.jsonl")).size(), 5u);
}

TEST(Pipeline, StopIsTheDefaultOnASourceError) {
    TempDir dir;
    Pipeline p(mockRig("  frames: 12\n  fail_after: 3\n  fail_for_ms: 200\n"), host());
    RunOptions o;
    o.out_dir = dir.str("out");
    o.progress = false;
    EXPECT_THROW(p.run(o), Error);
    const Json summary = Json::parse(readTextFile(dir.str("out/summary.json")));
    EXPECT_EQ(summary["status"], "failed");
    EXPECT_EQ(summary["frame_count"], 3);
    EXPECT_NE(summary["error"].get<std::string>().find("BINOCLE_ERR_DEVICE"), std::string::npos) << summary.dump(2);
}

TEST(Pipeline, LatestFrameObserverSkipsWhileItsConsumerIsBehind) {
    Pipeline p(mockRig("  frames: 10\n"), host());
    LatestFrame latest;
    p.addObserver(&latest);
    RunOptions o;
    o.progress = false;
    p.run(o);
    // Nobody took a frame during the run: the first was kept, the other nine skipped.
    EXPECT_EQ(latest.skipped(), 9u);
    std::optional<FrameSnapshot> s = latest.take();
    ASSERT_TRUE(s.has_value());
    EXPECT_EQ(s->sequence, 0u);
    EXPECT_EQ(s->disparity.size(), cv::Size(64, 48));
    EXPECT_EQ(s->cloud.size(), 64u * 48u);
    EXPECT_FALSE(latest.take().has_value());
}

} // namespace
} // namespace binocle::test

namespace binocle::test {
namespace {

TEST(Pipeline, AFrameOfAnotherSizeMidRunIsRefusedNamingTheFrameAndBothSizes) {
    TempDir dir;
    Pipeline p(mockRig("  frames: 8\n  grow_after: 4\n"), host());
    RunOptions o;
    o.out_dir = dir.str("out");
    o.progress = false;
    try {
        p.run(o);
        FAIL() << "a 80x48 frame after 64x48 ones must not be processed";
    } catch (const Error &e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("frame 4 (sequence 4)"), std::string::npos) << what;
        EXPECT_NE(what.find("80x48"), std::string::npos) << what;
        EXPECT_NE(what.find("expected 64x48"), std::string::npos) << what;
    }
    const Json summary = Json::parse(readTextFile(dir.str("out/summary.json")));
    EXPECT_EQ(summary["status"], "failed");
    EXPECT_EQ(summary["frame_count"], 4); // the frames before it are kept
    EXPECT_EQ(readLines(dir.str("out/frames.jsonl")).size(), 4u);
}

TEST(Pipeline, SummaryGivesEachStagesMedianAnd95thPercentileTimePerFrame) {
    TempDir dir;
    Pipeline p(mockRig("  frames: 20\n"), host());
    RunOptions o;
    o.out_dir = dir.str("out");
    o.progress = false;
    const Json summary = p.run(o);
    const Json written = Json::parse(readTextFile(dir.str("out/summary.json")));
    ASSERT_TRUE(written.contains("stage_seconds_per_frame")) << written.dump(2);
    const Json &stages = written["stage_seconds_per_frame"];
    std::vector<std::string> names;
    for (const auto &[name, t] : stages.items()) {
        names.push_back(name);
        EXPECT_EQ(t["frames"], 20) << name;
        EXPECT_GE(t["median"].get<double>(), 0.0) << name;
        EXPECT_LE(t["median"].get<double>(), t["p95"].get<double>()) << name;
        EXPECT_LT(t["p95"].get<double>(), 60.0) << name;
    }
    EXPECT_EQ(names, (std::vector<std::string>{"acquire", "rectify", "match", "cloud", "transforms", "evaluators", "write"}));
    EXPECT_EQ(summary["stage_seconds_per_frame"], stages);
}

TEST(StageTimes, MedianAnd95thPercentileByNearestRank) {
    StageTimes t;
    for (int i = 100; i >= 1; --i) t.add(i);
    EXPECT_EQ(t.count(), 100);
    EXPECT_EQ(t.quantile(0.5), 50);
    EXPECT_EQ(t.quantile(0.95), 95);
    EXPECT_EQ(t.quantile(1.0), 100);
    EXPECT_EQ(StageTimes().quantile(0.5), 0);
}

TEST(StageTimes, AnEndlessRunKeepsABoundedUniformSample) {
    StageTimes t;
    const int64_t n = 4 * static_cast<int64_t>(StageTimes::kKept);
    for (int64_t i = 0; i < n; ++i) t.add(static_cast<double>(i) / static_cast<double>(n)); // uniform on [0, 1)
    EXPECT_EQ(t.count(), n);
    EXPECT_NEAR(t.quantile(0.5), 0.5, 0.01);
    EXPECT_NEAR(t.quantile(0.95), 0.95, 0.01);
}

// Instances that write their name into a shared log when they go.
struct LoggedInstance {
    LoggedInstance(std::vector<std::string> &log, std::string name) : log_(log), name_(std::move(name)) {}
    ~LoggedInstance() { log_.push_back(name_); }
    std::vector<std::string> &log_;
    std::string name_;
};
struct FirstKind : LoggedInstance {
    using LoggedInstance::LoggedInstance;
};
struct SecondKind : LoggedInstance {
    using LoggedInstance::LoggedInstance;
};

TEST(PluginInstances, EachTypeHasItsOwnListAndAnAbsentOneReadsEmpty) {
    std::vector<std::string> log;
    PluginInstances p;
    EXPECT_TRUE(p.of<FirstKind>().empty());
    p.edit<FirstKind>().push_back(std::make_unique<FirstKind>(log, "a"));
    p.edit<FirstKind>().push_back(std::make_unique<FirstKind>(log, "b"));
    EXPECT_EQ(&p.edit<FirstKind>(), &p.of<FirstKind>()); // made once
    EXPECT_EQ(p.of<FirstKind>().size(), 2u);
    EXPECT_EQ(p.of<FirstKind>()[1]->name_, "b");
    EXPECT_TRUE(p.of<SecondKind>().empty()); // reading makes no list
    p.edit<SecondKind>().push_back(std::make_unique<SecondKind>(log, "c"));
    EXPECT_EQ(p.of<SecondKind>().size(), 1u);
    EXPECT_EQ(p.of<FirstKind>().size(), 2u);
    EXPECT_TRUE(log.empty());
}

TEST(PluginInstances, ListsGoInTheReverseOrderOfTheirMaking) {
    std::vector<std::string> log;
    {
        PluginInstances p;
        p.edit<FirstKind>().push_back(std::make_unique<FirstKind>(log, "first"));
        p.edit<SecondKind>().push_back(std::make_unique<SecondKind>(log, "second"));
    }
    EXPECT_EQ(log, (std::vector<std::string>{"second", "first"}));
}

} // namespace
} // namespace binocle::test
