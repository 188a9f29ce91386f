// SPDX-License-Identifier: MIT
// Accuracy of sgm (sparse and `fill: dense`), sgbm (sgbm_3way, block 5) and bm (block 15)
// on the 19 public pairs with ground truth of ../shared/data/stereo-gt (its INDEX.md and
// manifest.json; never copied into the repository). Per pair and matcher: bad-2 (error >
// 2 px) over the pixels with a disparity, density, and bad-2 counting holes as errors,
// over the non-occluded pixels where the pair has a mask (Middlebury 2001/2003
// nonocc.png == 255, 2014 mask0nocc.png == 255, KITTI disp_noc known), else over every
// pixel with ground truth (Middlebury 2005/2006). A hole is a disparity <= 0. The search
// range is the INDEX's ndisp: the least multiple of 16 above the largest known ground
// truth, min_disparity 0. Prints the table (plugins/sgm/README.md) and sets the means as
// counters; skipped when the folder is absent ($BINOCLE_STEREO_GT_DIR overrides it).
//   build/bench/binocle_bench --benchmark_filter=StereoGt
#include "bench_plugins.hpp"
#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"
#include "input/image_file.hpp"

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

fs::path stereoGtDir() {
    if (const char *dir = std::getenv("BINOCLE_STEREO_GT_DIR")) return dir;
    return fs::path(BINOCLE_SOURCE_DIR) / ".." / "shared" / "data" / "stereo-gt";
}

struct Pair {
    std::string name;
    cv::Mat left, right;
    cv::Mat truth; // CV_32F, pixels; <= 0 or not finite = unknown
    cv::Mat scored; // CV_8U: the pixels scored (non-occluded with ground truth, or all with it)
    int ndisp = 0;
};

Pair loadPair(const fs::path &root, const nlohmann::json &entry) {
    Pair p;
    p.name = entry.at("name").get<std::string>();
    const fs::path dir = root / p.name;
    p.left = cv::imread((dir / entry.at("left").get<std::string>()).string(), cv::IMREAD_GRAYSCALE);
    p.right = cv::imread((dir / entry.at("right").get<std::string>()).string(), cv::IMREAD_GRAYSCALE);
    const std::string format = entry.at("gt_format").get<std::string>();
    const fs::path gt = dir / entry.at("gt").get<std::string>();
    if (format == "pfm") {
        p.truth = binocle::input::readPfm(gt.string(), "ground truth"); // the scale's sign only (docs/benchmarks.md)
    } else {
        const cv::Mat raw = cv::imread(gt.string(), format == "png16" ? cv::IMREAD_UNCHANGED : cv::IMREAD_GRAYSCALE);
        if (raw.empty()) throw std::runtime_error(gt.string() + ": cannot be read");
        raw.convertTo(p.truth, CV_32F, 1.0 / entry.at("gt_scale").get<double>());
    }
    if (p.left.empty() || p.right.empty() || p.truth.size() != p.left.size())
        throw std::runtime_error(dir.string() + ": images missing or of another size than the ground truth");
    const cv::Mat known = (p.truth > 0) & (p.truth < std::numeric_limits<float>::infinity());
    const nlohmann::json &masks = entry.at("masks");
    cv::Mat nonocc;
    if (masks.contains("nonocc.png")) nonocc = cv::imread((dir / "nonocc.png").string(), cv::IMREAD_GRAYSCALE) == 255;
    else if (masks.contains("mask0nocc.png")) nonocc = cv::imread((dir / "mask0nocc.png").string(), cv::IMREAD_GRAYSCALE) == 255;
    else
        for (const auto &[file, meaning] : masks.items())
            if (file.rfind("disp_noc", 0) == 0) nonocc = cv::imread((dir / file).string(), cv::IMREAD_UNCHANGED) > 0;
    p.scored = nonocc.empty() ? known : (known & nonocc);
    double largest = 0;
    cv::minMaxLoc(p.truth, nullptr, &largest, nullptr, nullptr, known);
    p.ndisp = (static_cast<int>(largest) / 16 + 1) * 16;
    return p;
}

struct Score {
    double bad = 0, density = 0, badWithHoles = 0; // percent
};

Score score(const cv::Mat &d, const Pair &p) {
    double scored = 0, matched = 0, bad = 0;
    for (int y = 0; y < d.rows; ++y)
        for (int x = 0; x < d.cols; ++x) {
            if (!p.scored.at<uint8_t>(y, x)) continue;
            ++scored;
            const float v = d.at<float>(y, x);
            if (!(v > 0)) continue;
            ++matched;
            bad += std::fabs(v - p.truth.at<float>(y, x)) > 2.0f;
        }
    return {100 * bad / matched, 100 * matched / scored, 100 * (bad + scored - matched) / scored};
}

struct Contender {
    const char *label, *plugin, *yaml; // num_disparities is appended
};
const Contender kContenders[] = {{"sgm", "sgm", "{"},
                                 {"sgm_dense", "sgm", "{fill: dense, "},
                                 {"sgbm_3way", "sgbm", "{mode: sgbm_3way, block_size: 5, "},
                                 {"bm", "bm", "{block_size: 15, "}};
constexpr size_t kCount = sizeof kContenders / sizeof kContenders[0];

void BM_SgmAccuracyOnStereoGt(benchmark::State &state) {
    const fs::path root = stereoGtDir();
    std::ifstream manifestFile(root / "manifest.json");
    if (!manifestFile) {
        state.SkipWithError(("no " + (root / "manifest.json").string() + " (the shared stereo pairs)").c_str());
        return;
    }
    const nlohmann::json manifest = nlohmann::json::parse(manifestFile);
    for (auto _ : state) {
        std::vector<Score> sum(kCount);
        std::ostringstream table;
        table << "| pair | ndisp |";
        for (const Contender &c : kContenders) table << ' ' << c.label << " bad-2 / density / with holes |";
        table << "\n|---|---|";
        for (size_t i = 0; i < kCount; ++i) table << "---|";
        table << "\n";
        for (const nlohmann::json &entry : manifest) {
            const Pair p = loadPair(root, entry);
            table << "| " << p.name << " | " << p.ndisp << " |";
            for (size_t i = 0; i < kCount; ++i) {
                const binocle::PluginRecord &record =
                    binocle::bench::builtPlugins().require(kContenders[i].plugin, BINOCLE_KIND_MATCHER);
                binocle::Matcher m(record, binocle::paramsFromYaml(record, std::string(kContenders[i].yaml) +
                                                                           "num_disparities: " + std::to_string(p.ndisp) + "}"));
                const Score s = score(m.compute(p.left, p.right), p);
                sum[i].bad += s.bad;
                sum[i].density += s.density;
                sum[i].badWithHoles += s.badWithHoles;
                char cell[64];
                std::snprintf(cell, sizeof cell, " %.2f / %.1f / %.2f |", s.bad, s.density, s.badWithHoles);
                table << cell;
            }
            table << "\n";
        }
        const double n = static_cast<double>(manifest.size());
        table << "| **mean** | |";
        for (size_t i = 0; i < kCount; ++i) {
            char cell[64];
            std::snprintf(cell, sizeof cell, " **%.2f / %.1f / %.2f** |", sum[i].bad / n, sum[i].density / n,
                          sum[i].badWithHoles / n);
            table << cell;
            const std::string l = kContenders[i].label;
            state.counters[l + "_bad2_percent"] = sum[i].bad / n;
            state.counters[l + "_density_percent"] = sum[i].density / n;
            state.counters[l + "_bad2_holes_percent"] = sum[i].badWithHoles / n;
        }
        std::printf("%s\n", table.str().c_str());
    }
}
BENCHMARK(BM_SgmAccuracyOnStereoGt)->Iterations(1)->Unit(benchmark::kSecond);

} // namespace
