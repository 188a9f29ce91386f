// SPDX-License-Identifier: MIT
// Experiments over a dataset (`dataset:`, `scenes:`, `matcher:`, the benchmarks): a test
// per scene folder, a row per scene and the means, a bar per scene, on scenes made here
// (MiddEval3-shaped: im0/im1, disp0GT.pfm with Middlebury's -1/255 scale, mask0nocc.png).
#include "common/test_util.hpp"
#include "core/error.hpp"
#include "experiment/experiment.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <fstream>
#include <sstream>

using namespace binocle;
using binocle::test::runCli;
using binocle::test::TempDir;
using binocle::test::writeText;

namespace {

// A textured pair whose right image is the left one shifted by `shift` px, the ground
// truth `shift` everywhere (PFM as Middlebury writes it), all pixels non-occluded.
void writeScene(const std::filesystem::path &dir, int shift, int seed) {
    std::filesystem::create_directories(dir);
    cv::Mat left(48, 96, CV_8UC1);
    cv::RNG(seed).fill(left, cv::RNG::UNIFORM, 0, 256);
    cv::Mat right(left.size(), CV_8UC1, cv::Scalar(0));
    left.colRange(shift, left.cols).copyTo(right.colRange(0, left.cols - shift));
    cv::imwrite((dir / "im0.png").string(), left);
    cv::imwrite((dir / "im1.png").string(), right);
    cv::imwrite((dir / "mask0nocc.png").string(), cv::Mat(left.size(), CV_8UC1, cv::Scalar(255)));
    std::ofstream pfm(dir / "disp0GT.pfm", std::ios::binary);
    pfm << "Pf\n" << left.cols << " " << left.rows << "\n-0.003922\n";
    const float d = static_cast<float>(shift);
    for (int i = 0; i < left.total(); ++i) pfm.write(reinterpret_cast<const char *>(&d), 4);
}

std::string experiment(const TempDir &dir) {
    return "name: bench\nrig: " BINOCLE_SOURCE_DIR "/configs/rigs/benchmark-scene.yaml\nframes: 1\n"
           "dataset: " + dir.str("data") + "\nmatcher: {plugin: bm, num_disparities: 16, block_size: 7}\n"
           "charts:\n  - {type: bars, metric: disparity.bad_1px_nonocc_percent, file: bad1}\n";
}

std::vector<std::vector<std::string>> csv(const std::string &file) {
    std::ifstream in(file);
    std::vector<std::vector<std::string>> rows;
    for (std::string line; std::getline(in, line);) {
        std::vector<std::string> cells;
        std::stringstream s(line);
        for (std::string c; std::getline(s, c, ',');) cells.push_back(c);
        rows.push_back(cells);
    }
    return rows;
}

TEST(DatasetExperiment, ARowPerSceneThenTheMeansAndABarPerScene) {
    TempDir dir;
    writeScene(dir.path() / "data" / "b-scene", 5, 2);
    writeScene(dir.path() / "data" / "a-scene", 3, 1);
    writeText(dir.str("bench.yaml"), experiment(dir));
    auto r = runCli("experiment " + dir.str("bench.yaml") + " --quiet --out " + dir.str("out"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const auto rows = csv(dir.str("out/results.csv"));
    ASSERT_EQ(rows.size(), 4u);
    EXPECT_EQ(rows[1][0], "a-scene");
    EXPECT_EQ(rows[2][0], "b-scene");
    EXPECT_EQ(rows[3][0], "mean");
    const auto &header = rows[0];
    const size_t col = std::find(header.begin(), header.end(), "disparity.bad_1px_nonocc_percent") - header.begin();
    ASSERT_LT(col, header.size());
    EXPECT_EQ(std::find(header.begin(), header.end(), "form_factor"), header.end()) << "a scene has no geometry";
    const double a = std::stod(rows[1][col]), b = std::stod(rows[2][col]);
    EXPECT_NEAR(std::stod(rows[3][col]), (a + b) / 2, 1e-6);
    EXPECT_LT(a, 60) << "bm finds most of a 3 px shift (the left 16 columns are holes)";
    EXPECT_TRUE(std::filesystem::exists(dir.str("out/bad1.svg")));

    // scenes: picks some; a name the folder lacks is refused, naming the folder's scenes.
    r = runCli("experiment " + dir.str("bench.yaml") + " --quiet --set 'scenes=[b-scene]' --out " + dir.str("one"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(csv(dir.str("one/results.csv")).size(), 3u);
    // Shards merge into the same table, the means made again over all the scenes.
    for (const char *k : {"1", "2"}) {
        r = runCli("experiment " + dir.str("bench.yaml") + " --quiet --shard " + k + "/2 --out " + dir.str(std::string("shard") + k));
        ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    r = runCli("experiment merge " + dir.str("merged") + " " + dir.str("shard1") + " " + dir.str("shard2"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const auto merged = csv(dir.str("merged/results.csv"));
    ASSERT_EQ(merged.size(), 4u);
    EXPECT_EQ(merged[3][0], "mean");
    EXPECT_NEAR(std::stod(merged[3][col]), (a + b) / 2, 1e-6);

    r = runCli("experiment " + dir.str("bench.yaml") + " --quiet --set 'scenes=[c-scene]' --out " + dir.str("none"));
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.output.find("'c-scene' is not a folder of"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("a-scene, b-scene"), std::string::npos) << r.output;
}

TEST(DatasetExperiment, MatcherSwapsTheRigsMatcherBlockAndBadValuesAreRefused) {
    TempDir dir;
    writeScene(dir.path() / "data" / "s", 3, 1);
    writeText(dir.str("bench.yaml"), experiment(dir));
    PluginHost host;
    host.scan();
    Experiment e = loadExperiment(dir.str("bench.yaml"), host, {"matcher={plugin: sgbm, num_disparities: 32}"});
    const YAML::Node rig = rigForTest(e, e.tests.front());
    EXPECT_EQ(rig["matcher"]["plugin"].as<std::string>(), "sgbm");
    EXPECT_EQ(rig["matcher"]["num_disparities"].as<int>(), 32);
    EXPECT_FALSE(rig["matcher"]["block_size"]) << "the whole block is replaced, not merged";
    EXPECT_EQ(rig["source"]["folder"].as<std::string>(), dir.str("data/s"));
    // scene_set: a scene's own settings, over the swapped matcher.
    e = loadExperiment(dir.str("bench.yaml"), host, {"scene_set={s: {matcher.num_disparities: 48}}"});
    EXPECT_EQ(rigForTest(e, e.tests.front())["matcher"]["num_disparities"].as<int>(), 48);
    auto errorOf = [&](const std::vector<std::string> &set) {
        try {
            loadExperiment(dir.str("bench.yaml"), host, set);
        } catch (const std::exception &x) {
            return std::string(x.what());
        }
        return std::string();
    };
    EXPECT_NE(errorOf({"dataset=" + dir.str("nowhere")}).find("does not exist"), std::string::npos);
    EXPECT_NE(errorOf({"matcher=[1, 2]"}).find("matcher: expected a plugin name"), std::string::npos);
    EXPECT_NE(errorOf({"tests=[{id: 1}]"}).find("not with dataset:"), std::string::npos);
}

TEST(DatasetExperiment, TheBenchmarkExperimentsAreValid) {
    TempDir dir;
    writeScene(dir.path() / "data" / "kitti2012-000070", 3, 1); // the KITTI file names the shared pair
    for (const char *f : {"benchmark-middlebury", "benchmark-kitti"}) {
        auto r = runCli(std::string("experiment " BINOCLE_SOURCE_DIR "/configs/experiments/") + f +
                        ".yaml --check --set dataset=" + dir.str("data"));
        EXPECT_EQ(r.exit_code, 0) << f << ": " << r.output;
    }
}

} // namespace
