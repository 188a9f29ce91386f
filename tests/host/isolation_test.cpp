// SPDX-License-Identifier: MIT
// Matchers in a helper process (`isolation: process`): the same results as in process; a
// crash or a call past call_timeout_ms is an error naming the plugin, the call and the
// signal; `restart: true` restarts the helper; `binocle run` ends with its summary.
#include "fixture_host.hpp"

#include <chrono>

namespace binocle::test {
namespace {

using ::testing::HasSubstr;

// This executable is not in bin/, where the helper would be found next to it.
[[maybe_unused]] const int kHelper = ::setenv("BINOCLE_PLUGIN_HELPER", BINOCLE_PLUGIN_HELPER_PATH, 0);

std::unique_ptr<Matcher> isolatedMatcher(const std::string &name, const std::string &yaml, IsolationOptions o = {}) {
    const PluginRecord &record = fixture(name, BINOCLE_KIND_MATCHER);
    ParamValues params = paramsFromYaml(record, yaml);
    o.process = true;
    return std::make_unique<Matcher>(record, params, o);
}

// Wall-clock bounds are loose on purpose: CI machines are shared. They prove that a crash
// or a hang ends the call promptly instead of never; the figures on an idle machine are
// in the report of bench/bench_isolation.cpp and sdk/README.md.
constexpr double kPromptly = 10.0;

double secondsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

TEST(Isolation, ResultsEqualThoseInProcess) {
    auto isolated = isolatedMatcher("mock_matcher", "{mode: shift, disparity_px: 3}");
    auto local = newInstance<Matcher>("mock_matcher", BINOCLE_KIND_MATCHER, "{mode: shift, disparity_px: 3}");
    EXPECT_TRUE(isolated->isolated());
    for (const cv::Size size : {cv::Size(64, 48), cv::Size(640, 480), cv::Size(33, 17)}) {
        cv::Mat left(size, CV_8UC3, cv::Scalar(10, 20, 30));
        cv::Mat a = isolated->compute(left, left), b = local->compute(left, left);
        ASSERT_EQ(a.size(), size);
        EXPECT_EQ(cv::countNonZero(a != b), 0) << size;
        // The matcher's extra plane crosses too (after the disparity, in the shared memory).
        ASSERT_EQ(isolated->extras().size(), 1u) << size;
        ASSERT_EQ(local->extras().size(), 1u) << size;
        EXPECT_EQ(isolated->extras()[0].name, "mock_unmatched");
        EXPECT_EQ(cv::countNonZero(isolated->extras()[0].image != local->extras()[0].image), 0) << size;
        EXPECT_EQ(cv::countNonZero(local->extras()[0].image), 3 * size.height) << size;
    }
    EXPECT_EQ(isolated->disparityRange(), local->disparityRange());
}

// A matcher's extra planes are checked as matcher.h states them, in process and in a
// helper process alike: of the disparity's size, at most two FLOAT32 planes' worth.
TEST(Isolation, MatcherExtrasAreCheckedInProcessAndIsolated) {
    cv::Mat left(8, 8, CV_8UC1, cv::Scalar(0));
    for (const bool isolated : {false, true}) {
        auto half = isolated ? isolatedMatcher("faulty_matcher", "{fault: extras}")
                             : newInstance<Matcher>("faulty_matcher", BINOCLE_KIND_MATCHER, "{fault: extras}");
        const std::string msg = pluginErrorOf([&] { half->compute(left, left); });
        EXPECT_THAT(msg, HasSubstr("matcher plugin 'faulty_matcher'")) << isolated;
        EXPECT_THAT(msg, HasSubstr("extras failed (BINOCLE_ERR_INTERNAL): plane 'half' is 4x8: expected 8x8, the "
                                   "disparity's size")) << isolated;
        EXPECT_TRUE(half->extras().empty());
        auto many = isolated ? isolatedMatcher("faulty_matcher", "{fault: many_extras}")
                             : newInstance<Matcher>("faulty_matcher", BINOCLE_KIND_MATCHER, "{fault: many_extras}");
        EXPECT_THAT(pluginErrorOf([&] { many->compute(left, left); }),
                    HasSubstr("planes up to 'c' hold 768 bytes: expected at most 512, two FLOAT32 planes of the "
                              "disparity's size")) << isolated;
    }
}

TEST(Isolation, ThePluginsOwnErrorsCrossWithTheirCode) {
    auto m = isolatedMatcher("faulty_matcher", "{fault: throw}");
    cv::Mat left(8, 8, CV_8UC1, cv::Scalar(0));
    const std::string msg = pluginErrorOf([&] { m->compute(left, left); });
    EXPECT_THAT(msg, HasSubstr("matcher plugin 'faulty_matcher'"));
    EXPECT_THAT(msg, HasSubstr("compute failed (BINOCLE_ERR_INTERNAL): faulty_matcher: thrown on purpose"));
    // The helper is still alive: a bad setting is refused at create the same way.
    const PluginRecord &record = fixture("mock_matcher", BINOCLE_KIND_MATCHER);
    ParamValues bad = paramsFromYaml(record, "{}");
    bad.setText("mode", BINOCLE_PARAM_ENUM, "nonsense");
    IsolationOptions o;
    o.process = true;
    // The SDK checks the settings against the plugin's table before its constructor runs
    // (even one that takes raw Params, as mock_matcher's does): the refusal crosses from the
    // helper with the plugin's code and words, the same as in process.
    const std::string isolated = pluginErrorOf([&] { Matcher(record, bad, o); });
    EXPECT_THAT(isolated, HasSubstr("create failed (BINOCLE_ERR_INVALID_ARGUMENT): mock_matcher: mode = 'nonsense'"));
    const std::string inProcess = pluginErrorOf([&] { Matcher(record, bad, IsolationOptions{}); });
    EXPECT_EQ(isolated.substr(isolated.find("create failed")), inProcess.substr(inProcess.find("create failed")));
}

TEST(Isolation, ACrashInComputeNamesPluginCallAndSignal) {
    auto m = isolatedMatcher("faulty_matcher", "{fault: segfault, good_frames: 1}");
    cv::Mat left(16, 16, CV_8UC1, cv::Scalar(0));
    EXPECT_EQ(cv::countNonZero(m->compute(left, left) == 4.0f), 256); // the good frame
    const auto t0 = std::chrono::steady_clock::now();
    const std::string msg = pluginErrorOf([&] { m->compute(left, left); });
    EXPECT_LT(secondsSince(t0), kPromptly);
    EXPECT_THAT(msg, HasSubstr("matcher plugin 'faulty_matcher'"));
    EXPECT_THAT(msg, HasSubstr("compute crashed in its helper process (killed by signal 11 (SIGSEGV))"));
    // Later calls fail too, without hanging.
    EXPECT_THAT(pluginErrorOf([&] { m->compute(left, left); }), HasSubstr("gone"));
}

TEST(Isolation, ACallPastItsWatchdogIsKilled) {
    IsolationOptions o;
    o.call_timeout_ms = 300;
    auto m = isolatedMatcher("faulty_matcher", "{fault: hang}", o);
    cv::Mat left(16, 16, CV_8UC1, cv::Scalar(0));
    const auto t0 = std::chrono::steady_clock::now();
    const std::string msg = pluginErrorOf([&] { m->compute(left, left); });
    const double seconds = secondsSince(t0);
    EXPECT_GE(seconds, 0.3);
    EXPECT_LT(seconds, 0.3 + kPromptly);
    EXPECT_THAT(msg, HasSubstr("matcher plugin 'faulty_matcher'"));
    EXPECT_THAT(msg, HasSubstr("compute did not return within 300 ms (call_timeout_ms); its helper process was killed "
                               "(signal 9 (SIGKILL))"));
}

TEST(Isolation, RestartGivesAFreshHelperUpToMaxRestarts) {
    IsolationOptions o;
    o.restart = true;
    o.max_restarts = 2;
    auto m = isolatedMatcher("faulty_matcher", "{fault: segfault, good_frames: 1}", o);
    cv::Mat left(16, 16, CV_8UC1, cv::Scalar(0));
    EXPECT_EQ(cv::countNonZero(m->compute(left, left) == 4.0f), 256);
    // Crash -> restarted, that frame without disparity; the fresh instance has a good frame again.
    EXPECT_EQ(cv::countNonZero(m->compute(left, left) == BINOCLE_INVALID_DISPARITY), 256);
    EXPECT_EQ(cv::countNonZero(m->compute(left, left) == 4.0f), 256);
    EXPECT_EQ(cv::countNonZero(m->compute(left, left) == BINOCLE_INVALID_DISPARITY), 256);
    EXPECT_EQ(cv::countNonZero(m->compute(left, left) == 4.0f), 256);
    const std::string msg = pluginErrorOf([&] { m->compute(left, left); });
    EXPECT_THAT(msg, HasSubstr("killed by signal 11 (SIGSEGV)"));
    EXPECT_THAT(msg, HasSubstr("not restarted: 2 restart(s) already (max_restarts)"));
}

class IsolatedRun : public ::testing::Test {
protected:
    ProcessResult run(const std::string &matcherBlock) {
        writeText(dir_.str("rig.yaml"), "source:\n  plugin: mock_source\n  frames: 5\nmatcher:\n" + matcherBlock +
                                            "outputs:\n  disparity_png: false\n  disparity_color: false\n  cloud_ply: false\n");
        const auto t0 = std::chrono::steady_clock::now();
        ProcessResult r = runBinocle({"run", dir_.str("rig.yaml"), "--quiet", "--out", dir_.str("out")},
                                     std::string(BINOCLE_TEST_PLUGIN_DIR));
        seconds_ = secondsSince(t0);
        return r;
    }
    TempDir dir_;
    double seconds_ = 0;
};

TEST_F(IsolatedRun, SegfaultInComputeEndsTheRunCleanlyWithItsSummary) {
    const ProcessResult r = run("  plugin: faulty_matcher\n  fault: segfault\n  isolation: process\n");
    ASSERT_TRUE(r.exited) << "binocle was killed by signal " << r.signal << "\n" << r.err;
    EXPECT_NE(r.exit_code, 0);
    EXPECT_LT(seconds_, kPromptly);
    EXPECT_THAT(r.err, HasSubstr("matcher plugin 'faulty_matcher'"));
    EXPECT_THAT(r.err, HasSubstr("compute crashed in its helper process (killed by signal 11 (SIGSEGV))"));
    const std::string summary = readAll(dir_.str("out/summary.json"));
    EXPECT_THAT(summary, HasSubstr("\"status\": \"failed\""));
    EXPECT_THAT(summary, HasSubstr("SIGSEGV"));
}

TEST_F(IsolatedRun, ComputeThatNeverReturnsEndsAfterCallTimeout) {
    const ProcessResult r = run("  plugin: faulty_matcher\n  fault: hang\n  isolation: process\n  call_timeout_ms: 500\n");
    ASSERT_TRUE(r.exited) << r.err;
    EXPECT_NE(r.exit_code, 0);
    EXPECT_GE(seconds_, 0.5);
    EXPECT_LT(seconds_, 0.5 + kPromptly);
    EXPECT_THAT(r.err, HasSubstr("compute did not return within 500 ms (call_timeout_ms)"));
    EXPECT_THAT(readAll(dir_.str("out/summary.json")), HasSubstr("\"status\": \"failed\""));
}

TEST_F(IsolatedRun, RestartKeepsTheRunGoing) {
    const ProcessResult r =
        run("  plugin: faulty_matcher\n  fault: segfault\n  good_frames: 2\n  isolation: process\n  restart: true\n");
    ASSERT_TRUE(r.exited) << r.err;
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_THAT(r.err, HasSubstr("restarting its helper (1 of 3)"));
    const std::string summary = readAll(dir_.str("out/summary.json"));
    EXPECT_THAT(summary, HasSubstr("\"status\": \"ok\""));
}

TEST_F(IsolatedRun, IsolationKeysAreValidated) {
    ProcessResult r = run("  plugin: mock_matcher\n  isolation: sandbox\n");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_THAT(r.err, HasSubstr("matcher.isolation"));
    EXPECT_THAT(r.err, HasSubstr("value 'sandbox' is not valid: expected process or none"));
    r = run("  plugin: mock_matcher\n  call_timeout_ms: 100\n");
    EXPECT_THAT(r.err, HasSubstr("call_timeout_ms, restart and max_restarts need isolation: process"));
}

} // namespace
} // namespace binocle::test
