// SPDX-License-Identifier: MIT
// `binocle experiment FILE`: runs the tests of an experiment (METHOD.md E1, E2).
#include "cli/command.hpp"
#include "core/error.hpp"
#include "experiment/experiment.hpp"

#include <iostream>
#include <spdlog/spdlog.h>
#include <tuple>
#include <sstream>

namespace binocle::cli {
namespace {

// `binocle experiment merge OUT DIR...`
int merge(const Args &args) {
    const auto &p = args.positional();
    if (p.size() < 3) throw Error("expected: binocle experiment merge OUT DIR... (the output folders of the shards)");
    PluginHost host;
    host.scan();
    const Json result = mergeExperimentResults(p[1], std::vector<std::string>(p.begin() + 2, p.end()), host);
    const int64_t failed = static_cast<int64_t>(result.get("failed")->number());
    spdlog::info("experiment: {} test(s) merged from {} folder(s), {} failed; results in {}", result.get("tests")->number(),
                 p.size() - 2, failed, p[1]);
    return failed ? 1 : 0;
}

int run(const Args &args) {
    if (!args.positional().empty() && args.positional()[0] == "merge") return merge(args);
    if (args.positional().size() != 1) throw Error("expected one experiment file: binocle experiment FILE (see --help)");
    PluginHost host;
    host.scan();
    // Everything is checked before the first test runs.
    Experiment e = loadExperiment(args.positional()[0], host, args.all("--set"));
    ExperimentOptions options;
    if (args.has("--shard")) std::tie(options.shard_index, options.shard_count) = parseShard(args.get("--shard"));
    options.out_dir = args.get("--out", "out/" + e.name);
    options.progress = !args.has("--quiet");
    for (const auto &list : args.all("--tests")) {
        std::stringstream ss(list);
        for (std::string id; std::getline(ss, id, ',');)
            if (!id.empty()) options.only.push_back(id);
    }
    if (args.has("--check")) {
        std::cout << "experiment " << e.name << ": " << e.tests.size() << " tests, rig " << e.rig_file << ": valid\n";
        return 0;
    }
    Json result = runExperiment(e, host, options);
    const int64_t failed = static_cast<int64_t>(result.get("failed")->number());
    std::cerr << "experiment " << e.name << ": " << result.get("tests")->number() << " test(s) in "
              << static_cast<int>(result.get("seconds")->number()) << " s, " << failed << " failed; results in "
              << options.out_dir << " (results.csv, results.json, charts, test_<id>/)\n";
    return failed ? 1 : 0;
}

Register reg({"experiment", "run an experiment (E1, E2 of METHOD.md): a table of errors and efficiencies, charts",
              "usage: binocle experiment FILE [--out DIR] [--set KEY=VALUE]... [--tests ID,ID...] [--shard K/N] [--check] [--quiet]\n"
              "       binocle experiment merge OUT DIR...\n\n"
              "Runs each test of the experiment file: the base rig with the test's baseline,\n"
              "focal length, range, camera height and inclination. The whole file, and the rig\n"
              "of every test, is validated before anything runs. Writes into DIR (default\n"
              "out/<experiment name>):\n"
              "  results.csv, results.json   a row per test: B, f, R, FF, εx, εy, εz, η2D, η3D,\n"
              "                              valid-pixel ratio, time, and every evaluator figure\n"
              "  eta_3d_bars.png/.svg, eta_2d_bars.png/.svg, eta_3d_vs_ff.png/.svg   charts\n"
              "  test_<id>/                  disparity, PLY cloud, density views, summary.json\n"
              "The tables are rewritten after every test, so an interrupted run keeps its results.\n\n"
              "With repeats (repeats: N in the file, or --set repeats=N) every figure is the mean\n"
              "over N renderings with their own noise seed (and jitter: when the file asks), with\n"
              "<figure>_sd and the 95 % confidence interval <figure>_ci95_low/_high; charts carry\n"
              "error bars. calibration: board calibrates every configuration from chessboard pairs\n"
              "first. results.json holds Spearman's rho of each predictor against η3D.\n\n"
              "  --out DIR        output folder\n"
              "  --set KEY=VALUE  change a key of the experiment file (repeats=10, calibration=board,\n"
              "                   board_calibration.pairs=15, seed=7); repeatable\n"
              "  --shard K/N      run the K-th of N deterministic shares of the tests (position % N == K-1);\n"
              "                   join the shards' folders with `binocle experiment merge OUT DIR...`\n"
              "  --tests 1,5,9    run only these tests\n"
              "  --check          validate the file and stop\n"
              "  --quiet          no progress bar\n",
              {"--check", "--quiet"},
              run});

} // namespace
} // namespace binocle::cli
