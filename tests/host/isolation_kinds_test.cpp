// SPDX-License-Identifier: MIT
// Sources, cloud transforms and evaluators in a helper process (`isolation: process`):
// the same results as in process, crashes and hangs named with plugin, call and signal,
// restarts, the plugin's messages in Binocle's log, and `binocle run` from outside, which
// never opens an isolated plugin's file itself.
#include "fixture_host.hpp"

#include <chrono>
#include <nlohmann/json.hpp>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

namespace binocle::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// This executable is not in bin/, where the helper would be found next to it.
[[maybe_unused]] const int kHelper = ::setenv("BINOCLE_PLUGIN_HELPER", BINOCLE_PLUGIN_HELPER_PATH, 0);

// Loose on purpose (shared CI machines): a crash or a hang ends promptly, not never.
constexpr double kPromptly = 10.0;

double secondsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template <class Instance, class... Extra>
std::unique_ptr<Instance> isolated(const std::string &name, int32_t kind, const std::string &yaml, IsolationOptions o = {},
                                   Extra &&...extra) {
    const PluginRecord &record = fixture(name, kind);
    ParamValues params = paramsFromYaml(record, yaml);
    o.process = true;
    return std::make_unique<Instance>(record, params, std::forward<Extra>(extra)..., o);
}

cv::Mat copyOf(const cv::Mat &m) { return m.clone(); }

bool same(const cv::Mat &a, const cv::Mat &b) {
    return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// ---- Sources ----------------------------------------------------------------------------------

TEST(IsolatedSource, FramesEqualThoseInProcessAndLiveInAnotherProcess) {
    const std::string yaml = "{fault: none, frames: 4, width: 640, height: 480, disparity_px: 7}";
    auto local = newInstance<Source>("faulty_source", BINOCLE_KIND_STEREO_SOURCE, yaml);
    auto remote = isolated<Source>("faulty_source", BINOCLE_KIND_STEREO_SOURCE, yaml);
    EXPECT_TRUE(remote->isolated());
    EXPECT_FALSE(local->isolated());
    local->start();
    remote->start();
    EXPECT_EQ(local->calibration(), remote->calibration());
    // Several frames lent at once: each keeps its own pixels while later ones arrive.
    std::vector<std::unique_ptr<LentFrame>> mine, theirs;
    for (int i = 0; i < 4; ++i) {
        mine.push_back(local->grab(1000));
        theirs.push_back(remote->grab(1000));
        ASSERT_TRUE(mine.back() && theirs.back());
    }
    for (size_t i = 0; i < mine.size(); ++i) {
        const LentFrame &a = *mine[i], &b = *theirs[i];
        EXPECT_EQ(a.raw().sequence, b.raw().sequence);
        EXPECT_EQ(a.raw().timestamp_left_ns, b.raw().timestamp_left_ns);
        EXPECT_TRUE(same(a.left(), b.left())) << i;
        EXPECT_TRUE(same(a.right(), b.right())) << i;
        ASSERT_EQ(b.raw().extra_count, 1);
        EXPECT_STREQ(b.raw().extras[0].name, "gt_disparity");
        EXPECT_TRUE(same(a.extra("gt_disparity"), b.extra("gt_disparity"))) << i;
        const YAML::Node ma = YAML::Load(a.metadata()), mb = YAML::Load(b.metadata());
        EXPECT_EQ(ma["sequence"].as<int>(), mb["sequence"].as<int>());
        EXPECT_EQ(ma["pid"].as<int>(), ::getpid());
        EXPECT_NE(mb["pid"].as<int>(), ::getpid()); // grabbed in the helper process
    }
    EXPECT_EQ(local->grab(1000), nullptr); // end of stream, both ways
    EXPECT_EQ(remote->grab(1000), nullptr);
    EXPECT_EQ(YAML::Load(remote->statistics())["delivered"].as<int>(), 4);
    // A frame outlives its source: its copy is the host's.
    const cv::Mat kept = copyOf(theirs.front()->left());
    remote.reset();
    EXPECT_TRUE(same(kept, theirs.front()->left()));
}

TEST(IsolatedSource, ASegfaultInGrabNamesPluginCallAndSignal) {
    auto s = isolated<Source>("faulty_source", BINOCLE_KIND_STEREO_SOURCE, "{fault: segfault, good_frames: 1}");
    s->start();
    ASSERT_NE(s->grab(1000), nullptr);
    const auto t0 = std::chrono::steady_clock::now();
    const std::string msg = pluginErrorOf([&] { s->grab(1000); });
    EXPECT_LT(secondsSince(t0), kPromptly);
    EXPECT_THAT(msg, HasSubstr("source plugin 'faulty_source'"));
    EXPECT_THAT(msg, HasSubstr("grab crashed in its helper process (killed by signal 11 (SIGSEGV))"));
    EXPECT_THAT(pluginErrorOf([&] { s->statistics(); }), HasSubstr("its helper process is gone (grab crashed"));
}

TEST(IsolatedSource, AGrabPastItsWatchdogIsKilled) {
    IsolationOptions o;
    o.call_timeout_ms = 300;
    auto s = isolated<Source>("faulty_source", BINOCLE_KIND_STEREO_SOURCE, "{fault: hang}", o);
    s->start();
    const auto t0 = std::chrono::steady_clock::now();
    const std::string msg = pluginErrorOf([&] { s->grab(100); });
    const double seconds = secondsSince(t0);
    EXPECT_GE(seconds, 0.4); // its own wait, then the watchdog
    EXPECT_LT(seconds, 0.4 + kPromptly);
    EXPECT_THAT(msg, HasSubstr("source plugin 'faulty_source'"));
    EXPECT_THAT(msg, HasSubstr("grab did not return within 400 ms (its wait of 100 ms + call_timeout_ms); its helper "
                               "process was killed (signal 9 (SIGKILL))"));
}

TEST(IsolatedSource, RestartCreatesAndStartsTheSourceAgain) {
    IsolationOptions o;
    o.restart = true;
    o.max_restarts = 2;
    auto s = isolated<Source>("faulty_source", BINOCLE_KIND_STEREO_SOURCE, "{fault: segfault, good_frames: 2}", o);
    s->start();
    EXPECT_EQ(s->grab(1000)->raw().sequence, 0u);
    EXPECT_EQ(s->grab(1000)->raw().sequence, 1u);
    // The third grab crashes: a fresh instance is created, started, and delivers its first.
    EXPECT_EQ(s->grab(1000)->raw().sequence, 0u);
    EXPECT_EQ(s->restarts(), 1);
    EXPECT_EQ(s->lostCalls(), 1);
    EXPECT_EQ(s->grab(1000)->raw().sequence, 1u);
    EXPECT_EQ(s->grab(1000)->raw().sequence, 0u);
    const std::string msg = pluginErrorOf([&] {
        s->grab(1000);
        s->grab(1000);
    });
    EXPECT_THAT(msg, HasSubstr("grab crashed in its helper process (killed by signal 11 (SIGSEGV))"));
    EXPECT_THAT(msg, HasSubstr("not restarted: 2 restart(s) already (max_restarts)"));
}

TEST(IsolatedSource, ThePluginsOwnErrorsCrossWithTheirCode) {
    auto s = isolated<Source>("faulty_source", BINOCLE_KIND_STEREO_SOURCE, "{fault: throw}");
    const std::string msg = pluginErrorOf([&] { s->grab(10); });
    EXPECT_THAT(msg, HasSubstr("grab failed (BINOCLE_ERR_INTERNAL): faulty_source: thrown on purpose"));
    EXPECT_EQ(s->restarts(), 0);
    EXPECT_THAT(s->statistics(), HasSubstr("delivered: 0")); // still alive
}

// ---- Cloud transforms ------------------------------------------------------------------------

struct TestCloud {
    std::vector<float> xyz;
    std::vector<uint8_t> rgb;
    std::vector<int32_t> pixel;
    binocle_cloud view{};
    explicit TestCloud(int64_t n) : xyz(3 * n), rgb(3 * n), pixel(n) {
        for (int64_t i = 0; i < 3 * n; ++i) xyz[i] = static_cast<float>(i) * 0.5f, rgb[i] = static_cast<uint8_t>(i * 7);
        for (int64_t i = 0; i < n; ++i) pixel[i] = static_cast<int32_t>(i * 3);
        view = {n, xyz.data(), rgb.data(), pixel.data(), 64, 48, BINOCLE_FRAME_CAMERA};
    }
};

TEST(IsolatedTransform, ResultsEqualThoseInProcess) {
    auto local = newInstance<CloudTransform>("faulty_transform", BINOCLE_KIND_CLOUD_TRANSFORM, "{fault: none}");
    auto remote = isolated<CloudTransform>("faulty_transform", BINOCLE_KIND_CLOUD_TRANSFORM, "{fault: none}");
    for (int64_t n : {0, 1, 1001, 640 * 480}) {
        TestCloud a(n), b(n);
        local->apply(a.view);
        remote->apply(b.view);
        ASSERT_EQ(a.view.count, b.view.count) << n;
        EXPECT_EQ(a.view.count, (n + 1) / 2);
        EXPECT_EQ(a.xyz, b.xyz);
        EXPECT_EQ(a.rgb, b.rgb);
        EXPECT_EQ(a.pixel, b.pixel);
        EXPECT_EQ(b.view.xyz, b.xyz.data()); // rewritten in the host's own arrays
    }
}

TEST(IsolatedTransform, ACrashNamesPluginCallAndSignal_RestartDropsThatCloud) {
    auto t = isolated<CloudTransform>("faulty_transform", BINOCLE_KIND_CLOUD_TRANSFORM, "{fault: segfault}");
    TestCloud c(10);
    const std::string msg = pluginErrorOf([&] { t->apply(c.view); });
    EXPECT_THAT(msg, HasSubstr("transform plugin 'faulty_transform'"));
    EXPECT_THAT(msg, HasSubstr("apply crashed in its helper process (killed by signal 11 (SIGSEGV))"));

    IsolationOptions o;
    o.restart = true;
    auto r = isolated<CloudTransform>("faulty_transform", BINOCLE_KIND_CLOUD_TRANSFORM, "{fault: segfault, good_frames: 1}", o);
    TestCloud good(10), lost(10);
    r->apply(good.view);
    EXPECT_EQ(good.view.count, 5);
    r->apply(lost.view);
    EXPECT_EQ(lost.view.count, 0);
    EXPECT_EQ(r->restarts(), 1);
    EXPECT_EQ(r->lostCalls(), 1);
}

// ---- Evaluators -------------------------------------------------------------------------------

struct Figures {
    std::map<std::string, double> metrics;
    std::map<std::string, std::string> texts;
    HostSink sink() {
        HostSink s;
        s.metric = [this](const std::string &name, double v, const std::string &) { metrics[name] = v; };
        s.text = [this](const std::string &name, const std::string &t) { texts[name] = t; };
        return s;
    }
};

TEST(IsolatedEvaluator, FiguresEqualThoseInProcess) {
    // Everything an evaluator is given: a frame with an extra plane, images, a cloud, texts.
    cv::Mat left(48, 64, CV_8UC1), right(48, 64, CV_8UC1), rectified(48, 64, CV_8UC3), disparity(48, 64, CV_32F);
    cv::randu(left, 0, 255);
    cv::randu(right, 0, 255);
    cv::randu(rectified, 0, 255);
    cv::randu(disparity, -1.0, 60.0);
    cv::Mat gt(48, 64, CV_32F, cv::Scalar(3.5));
    auto image = [](const cv::Mat &m, int32_t format) {
        return binocle_image{m.cols, m.rows, static_cast<int32_t>(m.step[0]), format, m.data};
    };
    binocle_named_image extra{"gt_disparity", image(gt, BINOCLE_PIXEL_FLOAT32)};
    binocle_stereo_frame frame{};
    frame.struct_size = sizeof frame;
    frame.sequence = 17;
    frame.left = image(left, BINOCLE_PIXEL_GRAY8);
    frame.right = image(right, BINOCLE_PIXEL_GRAY8);
    frame.extras = &extra;
    frame.extra_count = 1;
    frame.metadata = "objects: []\n";
    const binocle_image rl = image(rectified, BINOCLE_PIXEL_BGR8), rr = frame.right, d = image(disparity, BINOCLE_PIXEL_FLOAT32);
    TestCloud cloud(777);
    const std::string rig(300 * 1024, 'r'); // more than one socket message
    binocle_eval_input in{};
    in.struct_size = sizeof in;
    in.frame = &frame;
    in.rectified_left = &rl;
    in.rectified_right = &rr;
    in.disparity = &d;
    in.cloud = &cloud.view;
    in.calibration_yaml = "%YAML:1.0\n";
    in.rig_yaml = rig.c_str();

    Figures a, b;
    const PluginRecord &record = fixture("faulty_evaluator", BINOCLE_KIND_EVALUATOR);
    auto local = std::make_unique<Evaluator>(record, paramsFromYaml(record, "{fault: none}"), a.sink());
    auto remote = isolated<Evaluator>("faulty_evaluator", BINOCLE_KIND_EVALUATOR, "{fault: none}", IsolationOptions{}, b.sink());
    for (int i = 0; i < 2; ++i) { // the second time, the texts are not sent again
        local->evaluate(in);
        remote->evaluate(in);
        EXPECT_EQ(a.metrics, b.metrics);
        EXPECT_EQ(a.texts, b.texts);
    }
    EXPECT_EQ(b.metrics["rig_bytes"], static_cast<double>(rig.size()));
    EXPECT_EQ(b.metrics["frame_extras_sum"], 3.5 * 64 * 48);
    EXPECT_EQ(b.texts["metadata"], "objects: []\n");
    in.calibration_yaml = nullptr; // and a change is
    local->evaluate(in);
    remote->evaluate(in);
    EXPECT_EQ(b.metrics["calibration_bytes"], -1);
    local->finish();
    remote->finish();
    EXPECT_EQ(a.metrics, b.metrics);
    EXPECT_EQ(b.metrics["frames_total"], 3);
}

TEST(IsolatedEvaluator, ACrashNamesPluginCallAndSignal) {
    Figures f;
    auto e = isolated<Evaluator>("faulty_evaluator", BINOCLE_KIND_EVALUATOR, "{fault: segfault}", IsolationOptions{}, f.sink());
    binocle_eval_input in{};
    in.struct_size = sizeof in;
    const std::string msg = pluginErrorOf([&] { e->evaluate(in); });
    EXPECT_THAT(msg, HasSubstr("evaluator plugin 'faulty_evaluator'"));
    EXPECT_THAT(msg, HasSubstr("evaluate crashed in its helper process (killed by signal 11 (SIGSEGV))"));
}

// ---- Messages ---------------------------------------------------------------------------------

TEST(IsolatedLog, ThePluginsMessagesAndOutputReachTheLogTagged) {
    std::ostringstream captured;
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(captured);
    sink->set_pattern("%l|%v");
    auto previous = spdlog::default_logger();
    spdlog::set_default_logger(std::make_shared<spdlog::logger>("test", sink));
    {
        auto s = isolated<Source>("faulty_source", BINOCLE_KIND_STEREO_SOURCE, "{fault: none}");
        s->statistics();
    }
    spdlog::set_default_logger(previous);
    const std::string log = captured.str();
    EXPECT_THAT(log, HasSubstr("info|[faulty_source] faulty_source: created in process "));
    EXPECT_THAT(log, Not(HasSubstr("created in process " + std::to_string(::getpid()) + "\n")));
    EXPECT_THAT(log, HasSubstr("info|[faulty_source] faulty_source: a line on stdout\n"));
    EXPECT_THAT(log, HasSubstr("warning|[faulty_source] faulty_source: a line on stderr\n"));
}

// ---- Binocle's process never opens an isolated plugin -----------------------------------------

TEST(IsolatedDescription, TheSettingsTableIsReadInAHelper) {
    PluginHost host(std::vector<std::string>{BINOCLE_TEST_PLUGIN_DIR});
    const PluginRecord *r = host.describe("faulty_source", BINOCLE_KIND_STEREO_SOURCE);
    ASSERT_NE(r, nullptr);
    EXPECT_TRUE(r->described);
    EXPECT_EQ(r->library, nullptr);
    EXPECT_TRUE(host.plugins().empty()); // nothing opened here
    EXPECT_EQ(r->version, "1.0.0");
    const PluginRecord &loaded = fixture("faulty_source", BINOCLE_KIND_STEREO_SOURCE);
    const auto a = r->params(), b = loaded.params();
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_STREQ(a[i].name, b[i].name);
        EXPECT_EQ(a[i].type, b[i].type);
        EXPECT_EQ(a[i].flags, b[i].flags);
        EXPECT_STREQ(a[i].default_value, b[i].default_value);
        EXPECT_EQ(a[i].min, b[i].min);
        EXPECT_STREQ(a[i].choices, b[i].choices);
        EXPECT_STREQ(a[i].help, b[i].help);
    }
    // An instance of a described record runs in a helper, whatever its settings say.
    Source s(*r, paramsFromYaml(*r, "{fault: none}"));
    EXPECT_TRUE(s.isolated());
    // A file that crashes or hangs at load is refused with the signal or the timeout.
    PluginHost unsafe(std::vector<std::string>{BINOCLE_TEST_UNSAFE_PLUGIN_DIR});
    EXPECT_EQ(unsafe.describe("crash_at_load"), nullptr);
    EXPECT_EQ(unsafe.describe("hang_at_load", 0, 500), nullptr);
    ASSERT_EQ(unsafe.refused().size(), 2u);
    EXPECT_THAT(unsafe.refused()[0].reason, HasSubstr("load crashed in its helper process (killed by signal"));
    EXPECT_THAT(unsafe.refused()[1].reason, HasSubstr("load did not return within 500 ms"));
}

// ---- `binocle run` from outside ---------------------------------------------------------------

class IsolatedRunKinds : public ::testing::Test {
protected:
    // blocks: YAML of source, matcher, transforms and evaluators, each ending in '\n'.
    ProcessResult run(const std::string &blocks, const std::string &out = "out", std::vector<std::string> extra = {}) {
        writeText(dir_.str("rig.yaml"), blocks + "outputs:\n  disparity_color: false\n  rectified_png: true\n");
        std::vector<std::string> args{"run", dir_.str("rig.yaml"), "--quiet", "--out", dir_.str(out)};
        args.insert(args.end(), extra.begin(), extra.end());
        const auto t0 = std::chrono::steady_clock::now();
        ProcessResult r = runBinocle(args, std::string(BINOCLE_TEST_PLUGIN_DIR));
        seconds_ = secondsSince(t0);
        return r;
    }
    nlohmann::json summary(const std::string &out = "out") { return nlohmann::json::parse(readAll(dir_.str(out + "/summary.json"))); }
    void expectFailedPromptly(const ProcessResult &r, const std::vector<std::string> &words) {
        ASSERT_TRUE(r.exited) << "binocle was killed by signal " << r.signal << "\n" << r.err;
        EXPECT_EQ(r.exit_code, 1) << r.err;
        EXPECT_LT(seconds_, kPromptly);
        for (const auto &w : words) EXPECT_THAT(r.err, HasSubstr(w));
        const nlohmann::json s = summary();
        EXPECT_EQ(s["status"], "failed");
        for (const auto &w : words) EXPECT_THAT(s["error"].get<std::string>(), HasSubstr(w));
    }
    TempDir dir_;
    double seconds_ = 0;
};

const std::string kMatcher = "matcher:\n  plugin: mock_matcher\n  mode: shift\n  disparity_px: 4\n";

TEST_F(IsolatedRunKinds, SegfaultInGrabEndsTheRunCleanlyWithItsSummary) {
    const ProcessResult r =
        run("source:\n  plugin: faulty_source\n  fault: segfault\n  good_frames: 2\n  isolation: process\n" + kMatcher);
    expectFailedPromptly(r, {"source plugin 'faulty_source'", "grab crashed in its helper process (killed by signal 11 (SIGSEGV))"});
    EXPECT_EQ(summary()["frame_count"], 2); // the frames delivered before the crash are finished
}

TEST_F(IsolatedRunKinds, GrabThatNeverReturnsEndsAfterItsWatchdog) {
    const ProcessResult r =
        run("source:\n  plugin: faulty_source\n  fault: hang\n  isolation: process\n  call_timeout_ms: 500\n" + kMatcher);
    expectFailedPromptly(r, {"source plugin 'faulty_source'", "grab did not return within", "call_timeout_ms",
                             "its helper process was killed (signal 9 (SIGKILL))"});
    EXPECT_GE(seconds_, 0.5);
}

TEST_F(IsolatedRunKinds, TransformCrashEndsTheRunCleanlyWithItsSummary) {
    const ProcessResult r = run("source:\n  plugin: faulty_source\n  fault: none\n" + kMatcher +
                                "transforms:\n  - plugin: faulty_transform\n    fault: segfault\n    isolation: process\n");
    expectFailedPromptly(r, {"transform plugin 'faulty_transform'", "apply crashed in its helper process (killed by signal 11 (SIGSEGV))"});
}

TEST_F(IsolatedRunKinds, EvaluatorCrashEndsTheRunCleanlyWithItsSummary) {
    const ProcessResult r = run("source:\n  plugin: faulty_source\n  fault: none\n" + kMatcher +
                                "evaluators:\n  - plugin: faulty_evaluator\n    fault: segfault\n    good_frames: 1\n"
                                "    isolation: process\n");
    expectFailedPromptly(r, {"evaluator plugin 'faulty_evaluator'",
                             "evaluate crashed in its helper process (killed by signal 11 (SIGSEGV))"});
}

TEST_F(IsolatedRunKinds, EveryKindIsolatedGivesTheSameOutputsAsInProcess) {
    auto rig = [](const std::string &isolation) {
        return "source:\n  plugin: faulty_source\n  fault: none\n  frames: 3\n" + isolation +
               "matcher:\n  plugin: mock_matcher\n  mode: shift\n  disparity_px: 4\n" + isolation +
               "transforms:\n  - plugin: faulty_transform\n    fault: none\n" + (isolation.empty() ? "" : "  ") + isolation +
               "evaluators:\n  - plugin: faulty_evaluator\n    fault: none\n" + (isolation.empty() ? "" : "  ") + isolation +
               "  - plugin: mock_evaluator\n" + (isolation.empty() ? "" : "  ") + isolation;
    };
    ProcessResult a = run(rig(""), "local");
    ASSERT_EQ(a.exit_code, 0) << a.err;
    ProcessResult b = run(rig("  isolation: process\n"), "isolated");
    ASSERT_EQ(b.exit_code, 0) << b.err;
    for (const std::string file : {"disparity_000001.png", "rectified_left_000002.png", "rectified_right_000000.png",
                                   "cloud_000000.ply", "cloud_000002.ply"})
        EXPECT_EQ(readAll(dir_.str("local/" + file)), readAll(dir_.str("isolated/" + file))) << file;
    const nlohmann::json sa = summary("local"), sb = summary("isolated");
    EXPECT_EQ(sa["metrics"], sb["metrics"]);
    EXPECT_EQ(sb["frame_count"], 3);
    EXPECT_FALSE(sa.contains("isolation"));
    for (const char *where : {"source", "matcher", "transforms[0]", "evaluators[0]"}) {
        EXPECT_EQ(sb["isolation"][where]["restarts"], 0) << where;
        EXPECT_EQ(sb["isolation"][where]["lost_calls"], 0) << where;
    }
    // Per frame, the evaluator saw the same (its metadata names the process, hence apart).
    std::istringstream la(readAll(dir_.str("local/frames.jsonl"))), lb(readAll(dir_.str("isolated/frames.jsonl")));
    int lines = 0;
    for (std::string x, y; std::getline(la, x) && std::getline(lb, y); ++lines) {
        nlohmann::json ja = nlohmann::json::parse(x), jb = nlohmann::json::parse(y);
        // The evaluator saw the matcher's extra plane, in process and isolated alike: 4
        // columns of the source's 64.
        for (const nlohmann::json *j : {&ja, &jb})
            EXPECT_DOUBLE_EQ((*j)["metrics"]["mock_evaluator"]["mock_unmatched_nonzero_percent"].get<double>(), 100.0 * 4 / 64)
                << *j;
        auto &ea = ja["metrics"]["faulty_evaluator"], &eb = jb["metrics"]["faulty_evaluator"];
        EXPECT_EQ(YAML::Load(ea["metadata"].get<std::string>())["sequence"].as<int>(),
                  YAML::Load(eb["metadata"].get<std::string>())["sequence"].as<int>());
        ea.erase("metadata");
        eb.erase("metadata");
        ea.erase("rig_bytes"); // the isolated rig's text is longer by its isolation keys
        eb.erase("rig_bytes");
        EXPECT_EQ(ea, eb);
        EXPECT_EQ(ja["points"], jb["points"]);
        EXPECT_GT(jb["points"].get<int>(), 0);
    }
    EXPECT_EQ(lines, 3);
}

TEST_F(IsolatedRunKinds, ARestartedSourceKeepsTheRunGoingAndIsCounted) {
    const ProcessResult r = run("source:\n  plugin: faulty_source\n  fault: segfault\n  good_frames: 2\n"
                                "  isolation: process\n  restart: true\n" + kMatcher,
                                "out", {"--frames", "5"});
    ASSERT_TRUE(r.exited) << r.err;
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_THAT(r.err, HasSubstr("grab crashed in its helper process (killed by signal 11 (SIGSEGV)); restarting its "
                                 "helper (1 of 3); that grab is lost"));
    const nlohmann::json s = summary();
    EXPECT_EQ(s["status"], "ok");
    EXPECT_EQ(s["frame_count"], 5);
    EXPECT_EQ(s["isolation"]["source"]["restarts"], 2);
    EXPECT_EQ(s["isolation"]["source"]["lost_calls"], 2);
}

TEST_F(IsolatedRunKinds, BinocleNeverLoadsAnIsolatedPluginItselfAndLogsItsOutputTagged) {
    fixtureHost(); // this test process opened the fixtures before the marker is set
    const std::string marker = dir_.str("loads.txt");
    ::setenv("BINOCLE_TEST_LOAD_MARKER", marker.c_str(), 1);
    const ProcessResult r = run("source:\n  plugin: faulty_source\n  fault: none\n  isolation: process\n" + kMatcher);
    ::unsetenv("BINOCLE_TEST_LOAD_MARKER");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Each line: the pid of a process that loaded the library, and its parent. Binocle is
    // this test's child; its helpers are Binocle's children.
    std::istringstream lines(readAll(marker));
    int loads = 0;
    for (int pid = 0, parent = 0; lines >> pid >> parent; ++loads) EXPECT_NE(parent, ::getpid()) << "binocle loaded it";
    EXPECT_GE(loads, 2); // the helper that read its settings table, and the one that ran it
    EXPECT_THAT(r.err, HasSubstr("binocle run: warning: [faulty_source] faulty_source: a line on stderr"));
    std::istringstream err(r.err);
    for (std::string line; std::getline(err, line);) EXPECT_NE(line.rfind("faulty_source:", 0), 0u) << "raw: " << line;
}

} // namespace
} // namespace binocle::test
