// SPDX-License-Identifier: MIT
// The `binocle` command over the fixture plugins, run as a child process: `plugins` lists
// what was accepted and what was refused with why, and `run` with a plugin that throws
// or returns garbage ends with exit code 1 and the plugin's message, not a signal.
#include "fixture_host.hpp"

#include "core/calibration.hpp"

#include <opencv2/imgcodecs.hpp>

namespace binocle::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr const char *kDeliberate = "deliberate failure from throws plugin";

// Exit code 1 with `message` on stderr, and no signal.
void expectCleanFailure(const ProcessResult &r, const std::string &message) {
    ASSERT_TRUE(r.exited) << "binocle was killed by signal " << r.signal << "\nstderr:\n" << r.err;
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_THAT(r.err, HasSubstr(message));
}

TEST(PluginsCommand, ListsAcceptedAndRefusedFixtures) {
    const ProcessResult r = runBinocle({"plugins"}, BINOCLE_TEST_PLUGIN_DIR);
    ASSERT_TRUE(r.exited) << r.err;
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto refusedAt = r.out.find("\nrefused:\n");
    ASSERT_NE(refusedAt, std::string::npos) << r.out;
    const std::string accepted = r.out.substr(0, refusedAt), refused = r.out.substr(refusedAt);

    EXPECT_THAT(r.out, HasSubstr("\n  " BINOCLE_TEST_PLUGIN_DIR "\n")); // the search path comes first
    for (const char *line : {"mock_source source", "mock_matcher matcher", "mock_transformtransform", "mock_evaluatorevaluator",
                             "c_matcher   matcher", "throws      matcher"}) {
        // Names longer than the column run into the kind: compare without the padding.
        std::string compact = accepted;
        compact.erase(std::remove(compact.begin(), compact.end(), ' '), compact.end());
        std::string want = line;
        want.erase(std::remove(want.begin(), want.end(), ' '), want.end());
        EXPECT_THAT(compact, HasSubstr("\n" + want + "1.0.0ABI" + std::to_string(BINOCLE_ABI_VERSION))) << line;
    }
    EXPECT_THAT(accepted, Not(HasSubstr("wrong_abi")));
    EXPECT_THAT(accepted, Not(HasSubstr("9.9.9"))); // the duplicate did not replace mock_matcher

    const std::string abi = std::to_string(BINOCLE_ABI_VERSION), next = std::to_string(BINOCLE_ABI_VERSION + 1);
    EXPECT_THAT(refused, HasSubstr("  " + fixturePath("wrong_abi") + ": built for ABI version " + next +
                                   ", but this host speaks ABI version " + abi));
    EXPECT_THAT(refused, HasSubstr("  " + fixturePath("no_init") + ": no init symbol '" BINOCLE_PLUGIN_INIT_SYMBOL "'"));
    EXPECT_THAT(refused, HasSubstr("  " + fixturePath("init_null") + ": init returned no table"));
    EXPECT_THAT(refused, HasSubstr("  " + fixturePath("null_entries") + ": plugin 'null_entries' leaves mandatory entries NULL: compute"));
    EXPECT_THAT(refused, HasSubstr("  " + fixturePath("small_header") + ": table size 8 is smaller than the plugin header"));
    EXPECT_THAT(refused, HasSubstr("  " + fixturePath("short_table") + ": table size"));
    EXPECT_THAT(refused, HasSubstr("  " + fixturePath("mock_matcher_duplicate") + ": plugin name 'mock_matcher' is already provided by " +
                                   fixturePath("mock_matcher")));
}

TEST(PluginsCommand, LoadOfARefusedFileFailsNamingIt) {
    const ProcessResult r = runBinocle({"plugins", "--load", fixturePath("wrong_abi")}, BINOCLE_TEST_PLUGIN_DIR);
    expectCleanFailure(r, "plugin file " + fixturePath("wrong_abi") + " refused: built for ABI version " +
                              std::to_string(BINOCLE_ABI_VERSION + 1));
}

// A rig of fixture plugins (and, for replay, the build's own plugins), written to a scratch dir.
class RunCommand : public ::testing::Test {
protected:
    ProcessResult run(const std::string &rigYaml, std::vector<std::string> extra = {}) {
        writeText(dir_.str("rig.yaml"), rigYaml);
        std::vector<std::string> args{"run", dir_.str("rig.yaml"), "--quiet"};
        args.insert(args.end(), extra.begin(), extra.end());
        return runBinocle(args, std::string(BINOCLE_TEST_PLUGIN_DIR) + ":" + BINOCLE_BUILD_PLUGIN_DIR);
    }
    TempDir dir_;
};

const char *kNoFiles = "outputs:\n  disparity_png: false\n  disparity_color: false\n  cloud_ply: false\n";

TEST_F(RunCommand, ThrowingMatcherFedByReplayFailsCleanly) {
    if (!std::filesystem::exists(std::string(BINOCLE_BUILD_PLUGIN_DIR) + "/binocle_replay.so"))
        GTEST_SKIP() << "the replay plugin is not built";
    const std::string left = std::string(BINOCLE_OPENCV_DATA_DIR) + "/aloeL.jpg";
    const std::string right = std::string(BINOCLE_OPENCV_DATA_DIR) + "/aloeR.jpg";
    const cv::Mat image = cv::imread(left);
    if (image.empty()) GTEST_SKIP() << left << " is not available";
    StereoCalibration::ideal(image.size(), 1870, 160).save(dir_.str("calibration.yml"));
    const ProcessResult r = run("source:\n  plugin: replay\n  layout: glob\n  left: " + left + "\n  right: " + right +
                                "\ncalibration: calibration.yml\nmatcher:\n  plugin: throws\n" + kNoFiles);
    expectCleanFailure(r, kDeliberate);
    EXPECT_THAT(r.err, HasSubstr("matcher plugin 'throws'"));
    EXPECT_THAT(r.err, HasSubstr("compute failed"));
}

TEST_F(RunCommand, ThrowingMatcherFedByMockSourceFailsCleanly) {
    const ProcessResult r = run(std::string("source:\n  plugin: mock_source\nmatcher:\n  plugin: throws\n") + kNoFiles,
                                {"--out", dir_.str("out")});
    expectCleanFailure(r, kDeliberate);
    // What was written before the failure says so.
    const std::string summary = readAll(dir_.str("out/summary.json"));
    EXPECT_THAT(summary, HasSubstr("\"status\": \"failed\""));
    EXPECT_THAT(summary, HasSubstr(kDeliberate));
}

TEST_F(RunCommand, ThrowingSourceFailsCleanly) {
    const ProcessResult r = run(std::string("source:\n  plugin: throws_source\nmatcher:\n  plugin: mock_matcher\n") + kNoFiles);
    expectCleanFailure(r, kDeliberate);
    EXPECT_THAT(r.err, HasSubstr("source plugin 'throws_source'"));
}

TEST_F(RunCommand, GarbageFrameFailsCleanly) {
    const ProcessResult r =
        run(std::string("source:\n  plugin: garbage_source\n  defect: small_stride\nmatcher:\n  plugin: mock_matcher\n") + kNoFiles);
    expectCleanFailure(r, "returned an invalid frame: right image has stride 4 bytes");
}

TEST_F(RunCommand, GarbageTransformFailsCleanly) {
    const ProcessResult r = run(std::string("source:\n  plugin: mock_source\nmatcher:\n  plugin: mock_matcher\n"
                                            "transforms:\n  - plugin: garbage_transform\n") +
                                kNoFiles);
    expectCleanFailure(r, "transform plugin 'garbage_transform'");
    EXPECT_THAT(r.err, HasSubstr("returned a garbage cloud"));
}

TEST_F(RunCommand, MocksRunEndToEnd) {
    // 64x48 pairs, f = 100 px, B = 100 mm, d = 4 px everywhere: 3072 points at 2.5 m,
    // every second one kept by mock_transform.
    const ProcessResult r = run(std::string("name: mocks\nsource:\n  plugin: mock_source\n  frames: 3\n"
                                            "matcher:\n  plugin: mock_matcher\n  disparity_px: 4\n"
                                            "transforms:\n  - plugin: mock_transform\n    keep_every: 2\n"
                                            "evaluators:\n  - plugin: mock_evaluator\n") +
                                kNoFiles,
                                {"--out", dir_.str("out")});
    ASSERT_TRUE(r.exited) << r.err;
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string summary = readAll(dir_.str("out/summary.json"));
    EXPECT_THAT(summary, HasSubstr("\"status\": \"ok\""));
    EXPECT_THAT(summary, HasSubstr("\"frame_count\": 3"));
    EXPECT_THAT(summary, HasSubstr("\"frames_total\": 3"));
    // Per-frame figures: one line per frame in frames.jsonl.
    const std::string frames = readAll(dir_.str("out/frames.jsonl"));
    EXPECT_EQ(std::count(frames.begin(), frames.end(), '\n'), 3);
    EXPECT_THAT(frames, HasSubstr("\"points\":1536"));
    EXPECT_THAT(frames, HasSubstr("\"cloud_points\":1536.0"));
    EXPECT_THAT(frames, HasSubstr("\"valid_disparity_percent\":100.0"));
    // Every frame the source lent came back.
    EXPECT_THAT(summary, HasSubstr("lent: 3\\nreleased: 3\\n"));
}

} // namespace
} // namespace binocle::test
