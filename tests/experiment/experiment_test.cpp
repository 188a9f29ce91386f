// SPDX-License-Identifier: MIT
// Experiments and design: validation before anything runs, tables and charts, ranking.
#include "common/test_util.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "experiment/experiment.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

using namespace binocle;
using binocle::test::runCli;
using binocle::test::TempDir;
using binocle::test::writeText;

namespace {

const std::string kRig = BINOCLE_SOURCE_DIR "/configs/rigs/sim-e1.yaml";

std::string experimentText(const std::string &tests) {
    return "name: small\nrig: " + kRig +
           "\nlenses_mm: [2.8, 4, 8, 12, 16]\nbaseline_range_mm: [100, 200]\n"
           "defaults: {camera_height_mm: 1500, inclination_deg: 0}\ntests:\n" +
           tests;
}

TEST(Experiment, ALensTheRigDoesNotHaveStopsBeforeAnythingRuns) {
    TempDir dir;
    const std::string file = dir.str("bad.yaml");
    writeText(file, experimentText("  - {id: 1, range_mm: 6000, baseline_mm: 100, focal_length_mm: 8}\n"
                                   "  - {id: 2, range_mm: 6000, baseline_mm: 100, focal_length_mm: 6}\n"));
    auto r = runCli("experiment " + file + " --quiet --out " + dir.str("out"));
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find(file + ":8:5: test 2: focal_length_mm = 6: the rig has no such lens"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.str("out"))) << "nothing may run or be written";
}

TEST(Experiment, NegativeRangeAndUnknownKeysAreRefusedWithLine) {
    PluginHost host;
    host.scan();
    TempDir dir;
    auto errorOf = [&](const std::string &tests) {
        writeText(dir.str("e.yaml"), experimentText(tests));
        try {
            loadExperiment(dir.str("e.yaml"), host);
        } catch (const Error &e) {
            return std::string(e.what());
        }
        return std::string();
    };
    std::string err = errorOf("  - {id: 7, range_mm: -6000, baseline_mm: 100, focal_length_mm: 8}\n");
    EXPECT_NE(err.find("e.yaml:7:5: test 7: range_mm = -6000: expected a positive range"), std::string::npos) << err;
    err = errorOf("  - {id: 1, range_m: 6000, baseline_mm: 100, focal_length_mm: 8}\n");
    EXPECT_NE(err.find("unknown key 'range_m'; did you mean 'range_mm'?"), std::string::npos) << err;
    err = errorOf("  - {id: 1, range_mm: 6000, baseline_mm: 250, focal_length_mm: 8}\n");
    EXPECT_NE(err.find("baseline_mm = 250: outside the rig's baseline range 100 .. 200 mm"), std::string::npos) << err;
    // An override that makes the test's rig invalid is caught before running too.
    err = errorOf("  - {id: 1, range_mm: 6000, baseline_mm: 100, focal_length_mm: 8, set: {matcher.num_disparities: 100}}\n");
    EXPECT_NE(err.find("test 1: its rig is invalid"), std::string::npos) << err;
    EXPECT_NE(err.find("multiple of 16"), std::string::npos) << err;
}

TEST(Experiment, TheShippedExperimentsAreValid) {
    for (const char *f : {"e1", "e2"}) {
        auto r = runCli(std::string("experiment " BINOCLE_SOURCE_DIR "/configs/experiments/") + f + ".yaml --check");
        EXPECT_EQ(r.exit_code, 0) << r.output;
    }
    PluginHost host;
    host.scan();
    Experiment e1 = loadExperiment(BINOCLE_SOURCE_DIR "/configs/experiments/e1.yaml", host);
    ASSERT_EQ(e1.tests.size(), 16u);
    EXPECT_DOUBLE_EQ(e1.tests[7].geometry.focal_length_mm, 12); // Test 8: 150 mm, 12 mm, 6 m
    EXPECT_DOUBLE_EQ(e1.tests[7].geometry.baseline_mm, 150);
    EXPECT_EQ(loadExperiment(BINOCLE_SOURCE_DIR "/configs/experiments/e2.yaml", host).tests.size(), 8u);
}

TEST(Experiment, RunWritesTablesChartsAndPerTestOutputs) {
    TempDir dir;
    const std::string file = dir.str("two.yaml");
    writeText(file, experimentText("  - {id: a, range_mm: 6000, baseline_mm: 100, focal_length_mm: 8}\n"
                                   "  - {id: b, range_mm: 12000, baseline_mm: 190, focal_length_mm: 12}\n"));
    auto r = runCli("experiment " + file + " --quiet --out " + dir.str("out"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string csv = readTextFile(dir.str("out/results.csv"));
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;
    for (const char *col : {"baseline_mm", "focal_length_mm", "range_mm", "form_factor", "epsilon_x_percent", "epsilon_y_percent",
                            "epsilon_z_percent", "eta_2d_percent", "eta_3d_percent", "valid_pixel_ratio", "seconds"})
        EXPECT_NE(csv.find(col), std::string::npos) << col;
    // FF of test a: 10 * 100 * 8 / 6000 (Eq. 7).
    EXPECT_NE(csv.find("a,ok,100,8,6000,1500,0,1.33333"), std::string::npos) << csv;
    EXPECT_NE(readTextFile(dir.str("out/results.json")).find("\"test\": \"b\""), std::string::npos);
    for (const char *chart : {"eta_3d_bars", "eta_2d_bars", "eta_3d_vs_ff"}) {
        EXPECT_FALSE(cv::imread(dir.str("out/") + chart + ".png").empty()) << chart;
        EXPECT_NE(readTextFile(dir.str("out/") + chart + ".svg").find("<svg"), std::string::npos) << chart;
    }
    EXPECT_TRUE(std::filesystem::exists(dir.str("out/test_a/cloud_000000.ply")));
    EXPECT_TRUE(std::filesystem::exists(dir.str("out/test_b/summary.json")));
}

TEST(Design, RanksByFormFactorAndRefusesBadInput) {
    TempDir dir;
    auto r = runCli("design --range 6000 --lenses 2.8,8,16 --baselines 100,150 --top 3 --out " + dir.str());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // At 6 m, B 150 and f 8 give FF = 2.0, the only configuration inside the best band 1.2-2.0.
    const auto first = r.output.find("\n1 ");
    ASSERT_NE(first, std::string::npos) << r.output;
    EXPECT_NE(r.output.substr(first, 40).find("150     8.0    2.00"), std::string::npos) << r.output;
    EXPECT_NE(readTextFile(dir.str("design.json")).find("\"form_factor\": 2"), std::string::npos);
    EXPECT_EQ(runCli("design").exit_code, 2); // usage: no target
    auto bad = runCli("design --range 6000 --lenses 8,x");
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.output.find("'x' is not a number"), std::string::npos) << bad.output;
}

TEST(Design, SimulateRanksByMeasuredEfficiency) {
    TempDir dir;
    auto r = runCli("design --range 6000 --lenses 2.8,8 --baselines 100 --simulate --quiet --out " + dir.str());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(std::filesystem::exists(dir.str("simulated/results.csv")));
    EXPECT_NE(readTextFile(dir.str("design.json")).find("eta_3d_percent"), std::string::npos);
}

} // namespace
