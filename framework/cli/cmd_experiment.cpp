// SPDX-License-Identifier: MIT
// `binocle experiment FILE`: runs the tests of an experiment (METHOD.md E1, E2).
#include "app/experiment_run.hpp"
#include "cli/command.hpp"
#include "core/error.hpp"
#include "report/html_report.hpp"

#include <spdlog/spdlog.h>

#include <iostream>

namespace binocle::cli {
namespace {

struct ExperimentArgs {
    app::ExperimentRequest request; // file, set, tests, shard, out, force
    bool check = false, quiet = false, report = false;
    std::vector<std::string> merge; // `experiment merge OUT DIR...`
};

int merge(const std::vector<std::string> &p, bool force) {
    if (p.size() < 2) throw Error("expected: binocle experiment merge OUT DIR... (the output folders of the shards)");
    app::MergeRequest request;
    request.out = p[0];
    request.folders.assign(p.begin() + 1, p.end());
    request.force = force;
    const ExperimentResult result = app::mergeExperiment(request);
    spdlog::info("experiment: {} test(s) merged from {} folder(s), {} failed; results in {}", result.rows.size(), p.size() - 1,
                 result.failed, p[0]);
    return result.failed ? 1 : 0;
}

int experiment(ExperimentArgs args) {
    if (!args.merge.empty()) return merge(args.merge, args.request.force);
    if (args.request.file.empty()) throw Error("expected an experiment file: binocle experiment FILE (see --help)");
    args.request.progress = !args.quiet;
    if (args.check) {
        PluginHost host;
        // Everything is checked, nothing runs.
        const Experiment e = app::loadExperiment(args.request, host);
        std::cout << "experiment " << e.name << ": " << e.tests.size() << " tests, rig " << e.rig_file << ": valid\n";
        return 0;
    }
    app::ExperimentRun run(args.request);
    const ExperimentResult result = run.run();
    spdlog::info("experiment {}: {} test(s) in {} s, {} failed; results in {} (results.csv, results.json, charts, test_<id>/)",
                 run.experiment().name, result.rows.size(), static_cast<int>(result.seconds), result.failed, run.out());
    if (args.report) spdlog::info("report: {}", report::writeExperimentReport(run.out()));
    return result.failed ? 1 : 0;
}

Register experimentCommand{{"experiment", "run an experiment (E1, E2 of METHOD.md): a table of errors and efficiencies, charts",
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
              "first. results.json holds Spearman's rho of each predictor against η3D.\n"
              "`binocle experiment merge OUT DIR...` joins the folders of --shard runs.\n\n"
              "Over a dataset (dataset: FOLDER, the benchmarks configs/experiments/benchmark-*.yaml):\n"
              "a test per scene folder, a row per scene and a row `mean`, a bar per scene;\n"
              "--set dataset=DIR --set 'matcher={plugin: NAME, ...}' measures any matcher.",
              define<ExperimentArgs>(
                  [](CLI::App &app, ExperimentArgs &args) {
                      app.add_option("file", args.request.file, "the experiment file (YAML)")->type_name("FILE");
                      app.add_option("--set", args.request.set,
                                     "change a key of the experiment file (repeats=10, calibration=board, "
                                     "board_calibration.pairs=15, seed=7, rig_set.source.image_width=640, dataset=DIR, matcher=sgm); repeatable")
                          ->type_name("KEY=VALUE")
                          ->allow_extra_args(false);
                      app.add_option("--shard", args.request.shard,
                                     "run the K-th of N deterministic shares of the tests (position % N == K-1); join the "
                                     "shards with `binocle experiment merge OUT DIR...`")
                          ->type_name("K/N")
                          ->check(wholeNumbers('/', 1));
                      auto *m = app.add_subcommand("merge", "join the output folders of shards into OUT: the same rows as "
                                                            "one unsharded run (timings apart)");
                      m->add_option("folders", args.merge, "OUT DIR...")->required()->expected(2, -1);
                      app.add_option("--out", args.request.out, "output folder (default out/<experiment name>)")->type_name("DIR");
                      app.add_option("--tests", args.request.tests, "run only these tests, e.g. --tests 1,5,9")
                          ->type_name("ID,ID...")
                          ->delimiter(',')
                          ->allow_extra_args(false);
                      app.add_flag("--check", args.check, "validate the file and stop");
                      app.add_flag("--force", args.request.force, "replace the results of another experiment in the output folder");
                      m->add_flag("--force", args.request.force, "replace the results already in OUT");
                      app.add_flag("--quiet", args.quiet, "no progress display");
                      app.add_flag("--report", args.report, "also write DIR/report.html (as `binocle report DIR`)");
                  },
                  experiment)}};

} // namespace
} // namespace binocle::cli
