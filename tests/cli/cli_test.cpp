// SPDX-License-Identifier: MIT
// The `binocle` command end to end: help, plugins, and a run on the real opencv-doc
// pair checked against its ground-truth disparity.
#include "common/test_util.hpp"
#include "files/atomic_file.hpp"
#include "core/cloud.hpp"
#include "core/image_io.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

using binocle::test::runCli;
using binocle::test::TempDir;

namespace {

TEST(Cli, EveryCommandHasHelp) {
    auto top = runCli("--help");
    ASSERT_EQ(top.exit_code, 0) << top.output;
    for (const char *cmd : {"plugins", "run"}) {
        EXPECT_NE(top.output.find(cmd), std::string::npos) << cmd;
        auto r = runCli(std::string(cmd) + " --help");
        EXPECT_EQ(r.exit_code, 0) << r.output;
        EXPECT_NE(r.output.find("usage: binocle " + std::string(cmd)), std::string::npos) << r.output;
    }
    EXPECT_EQ(runCli("frobnicate").exit_code, 2);
}

TEST(Cli, PluginsListsTheBuiltInOnesWithVersions) {
    auto r = runCli("plugins");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char *name : {"replay", "bm", "sgbm", "ground"}) {
        EXPECT_NE(r.output.find(std::string("  ") + name + " "), std::string::npos) << name << "\n" << r.output;
    }
    EXPECT_NE(r.output.find("ABI 1 API 1"), std::string::npos) << r.output;
}

TEST(Cli, RunOnTheOpenCvPairMatchesGroundTruth) {
    TempDir out;
    auto r = runCli("run " BINOCLE_SOURCE_DIR "/configs/rigs/opencv-aloe.yaml --quiet --set 'evaluators.0.thresholds_px=[3]' --out " +
                    out.str());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char *f : {"disparity_000000.png", "disparity_color_000000.png", "cloud_000000.ply", "summary.json"})
        EXPECT_TRUE(std::filesystem::exists(out.path() / f)) << f;

    // 16-bit KITTI PNG against the 8-bit ground truth (disparity in px, 0 = unknown).
    cv::Mat d = binocle::readDisparityPng16(out.str("disparity_000000.png"));
    cv::Mat gt = cv::imread(BINOCLE_OPENCV_DATA_DIR "/aloeGT.png", cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(d.size(), gt.size());
    int64_t known = 0, compared = 0, bad = 0;
    for (int v = 0; v < d.rows; ++v)
        for (int u = 0; u < d.cols; ++u) {
            if (gt.at<uint8_t>(v, u) == 0) continue;
            ++known;
            const float x = d.at<float>(v, u);
            if (!(x > 0)) continue;
            ++compared;
            if (std::abs(x - gt.at<uint8_t>(v, u)) > 3.0f) ++bad;
        }
    const double density = double(compared) / known, badRate = double(bad) / compared;
    std::cout << "aloe sgbm: density " << density << ", bad (>3 px) " << badRate << "\n";
    // Measured: density 0.70, bad-3px 2.7 % (sgbm, 256 disparities, block 5).
    EXPECT_GT(density, 0.65);
    EXPECT_LT(badRate, 0.10);

    binocle::Cloud cloud = binocle::readPly(out.str("cloud_000000.ply"));
    EXPECT_EQ(cloud.frame, BINOCLE_FRAME_GROUND);
    EXPECT_GT(cloud.size(), 500000u);
    const std::string summary = binocle::test::runCommand("cat " + out.str("summary.json")).output;
    EXPECT_NE(summary.find("\"status\": \"ok\""), std::string::npos) << summary;
    // The disparity evaluator, computed in the plugin, agrees with this test's own count,
    // holes counted as errors (the PNG rounds disparities to 1/256 px, hence the tolerance).
    const std::string key = "\"bad_3px_all_percent\": ";
    const auto pos = summary.find(key);
    ASSERT_NE(pos, std::string::npos) << summary;
    EXPECT_NEAR(std::stod(summary.substr(pos + key.size())), 100.0 * double(bad + known - compared) / known, 0.05) << summary;
}

TEST(Cli, RunOnAMissingRigFailsWithTheFileName) {
    auto r = runCli("run /nonexistent/rig.yaml");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("/nonexistent/rig.yaml does not exist"), std::string::npos) << r.output;
}

TEST(Cli, MisspeltKeyOnTheCommandLineIsReported) {
    auto r = runCli("run " BINOCLE_SOURCE_DIR "/configs/rigs/opencv-aloe.yaml --set matcher.num_disparity=64");
    EXPECT_EQ(r.exit_code, 2) << r.output; // a usage error, as every bad --set
    EXPECT_NE(r.output.find("did you mean 'num_disparities'"), std::string::npos) << r.output;
}

const std::string kAloe = BINOCLE_SOURCE_DIR "/configs/rigs/opencv-aloe.yaml";
const std::string kSim = BINOCLE_SOURCE_DIR "/configs/rigs/sim-videre.yaml";

TEST(Cli, UnknownOptionsAreUsageErrorsNamingTheOption) {
    auto r = runCli("run " + kAloe + " --bogus x");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("unknown option '--bogus'"), std::string::npos) << r.output;

    r = runCli("run " + kAloe + " --frame 2");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("unknown option '--frame'; did you mean '--frames'?"), std::string::npos) << r.output;

    r = runCli("run " + kAloe + " --frame=2");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("did you mean '--frames'?"), std::string::npos) << r.output;

    r = runCli("run " + kAloe + " " + kAloe);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("unexpected argument"), std::string::npos) << r.output;

    r = runCli("plugins --verbos");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("did you mean '--verbose'?"), std::string::npos) << r.output;

    r = runCli("experment");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("did you mean 'experiment'?"), std::string::npos) << r.output;
}

TEST(Cli, NumericOptionsAreValidated) {
    for (const char *bad : {"--frames -5", "--frames 0", "--frames two", "--frames 1.5"}) {
        auto r = runCli("run " + kAloe + " " + bad);
        EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.output;
        EXPECT_NE(r.output.find("--frames"), std::string::npos) << r.output;
    }
    auto r = runCli("design --range 6000 --pixel-pitch-um -3");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--pixel-pitch-um"), std::string::npos) << r.output;
}

TEST(Cli, HelpAndVersionComeFromTheParser) {
    auto r = runCli("run --help");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char *option : {"--frames", "--out", "--set", "--quiet", "--log-level", "--log-file"})
        EXPECT_NE(r.output.find(option), std::string::npos) << option << "\n" << r.output;
    r = runCli("--version");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("binocle 0."), std::string::npos) << r.output;
    r = runCli("");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("usage: binocle"), std::string::npos) << r.output;
}

TEST(Cli, PluginDebugLinesAreTaggedAndShownAtDebugOnly) {
    binocle::test::TempDir dir;
    auto r = runCli("--log-level debug run " + kSim + " --frames 1 --quiet --log-file " + dir.str("log.txt"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("debug: [sim] frame 0 rendered in"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("debug: [sgbm] block_size"), std::string::npos) << r.output;
    const std::string log = binocle::readTextFile(dir.str("log.txt"));
    EXPECT_NE(log.find("[debug] [sim] frame 0 rendered in"), std::string::npos) << log;

    // The same through the environment, and the option after the command.
    r = binocle::test::runCommand("BINOCLE_LOG_LEVEL=debug BINOCLE_PLUGIN_PATH='" BINOCLE_BUILD_PLUGIN_DIR "' '" BINOCLE_CLI
                                  "' run " + kSim + " --frames 1 --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("[sim] frame 0 rendered"), std::string::npos) << r.output;

    r = runCli("run " + kSim + " --frames 1 --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("[sim]"), std::string::npos) << r.output; // info by default
    r = runCli("run " + kSim + " --frames 1 --quiet --log-level warn");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("frame(s) of rig"), std::string::npos) << r.output;

    r = runCli("--log-level loud plugins");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--log-level 'loud'"), std::string::npos) << r.output;
}

TEST(Cli, BashCompletionKnowsCommandsAndOptions) {
    binocle::test::TempDir dir;
    auto r = runCli("completion bash > " + dir.str("binocle.bash"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // Completes like bash would: the words typed so far, then the function.
    auto complete = [&](const std::string &words) {
        const std::string script = "source " + dir.str("binocle.bash") + "; COMP_WORDS=(" + words +
                                   "); COMP_CWORD=$((${#COMP_WORDS[@]} - 1)); _binocle; echo \"${COMPREPLY[*]}\"";
        return binocle::test::runCommand("bash -c '" + script + "'").output;
    };
    EXPECT_NE(complete("binocle exp").find("experiment"), std::string::npos);
    EXPECT_NE(complete("binocle run rig.yaml --fr").find("--frames"), std::string::npos) << complete("binocle run rig.yaml --fr");
    EXPECT_NE(complete("binocle --log-level d").find("debug"), std::string::npos);
    EXPECT_EQ(complete("binocle run rig.yaml --fr").find("--frames-"), std::string::npos);
    EXPECT_EQ(runCli("completion zsh").exit_code, 2);
}

} // namespace
