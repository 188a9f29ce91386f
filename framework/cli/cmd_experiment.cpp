// SPDX-License-Identifier: MIT
// `binocle experiment FILE`: runs the tests of an experiment (METHOD.md E1, E2).
#include "cli/command.hpp"
#include "experiment/experiment.hpp"
#include "report/html_report.hpp"

#include <spdlog/spdlog.h>

#include <iostream>

namespace binocle::cli {
namespace {

struct ExperimentArgs {
    std::string file, out;
    std::vector<std::string> tests;
    bool check = false, quiet = false, report = false;
};

int experiment(const ExperimentArgs &args) {
    PluginHost host;
    host.scan();
    // Everything is checked before the first test runs.
    Experiment e = loadExperiment(args.file, host);
    if (args.check) {
        std::cout << "experiment " << e.name << ": " << e.tests.size() << " tests, rig " << e.rig_file << ": valid\n";
        return 0;
    }
    ExperimentOptions options;
    options.out_dir = args.out.empty() ? "out/" + e.name : args.out;
    options.progress = !args.quiet;
    for (const auto &id : args.tests)
        if (!id.empty()) options.only.push_back(id);
    const ExperimentResult result = runExperiment(e, host, options);
    spdlog::info("experiment {}: {} test(s) in {} s, {} failed; results in {} (results.csv, results.json, charts, test_<id>/)",
                 e.name, result.rows.size(), static_cast<int>(result.seconds), result.failed, options.out_dir);
    if (args.report) spdlog::info("report: {}", report::writeExperimentReport(options.out_dir));
    return result.failed ? 1 : 0;
}

Register reg{{"experiment", "run an experiment (E1, E2 of METHOD.md): a table of errors and efficiencies, charts",
              "Runs each test of the experiment file: the base rig with the test's baseline,\n"
              "focal length, range, camera height and inclination. The whole file, and the rig\n"
              "of every test, is validated before anything runs. Writes into DIR (default\n"
              "out/<experiment name>):\n"
              "  results.csv, results.json   a row per test: B, f, R, FF, εx, εy, εz, η2D, η3D,\n"
              "                              valid-pixel ratio, time, and every evaluator figure\n"
              "  eta_3d_bars.png/.svg, eta_2d_bars.png/.svg, eta_3d_vs_ff.png/.svg   charts\n"
              "  test_<id>/                  disparity, PLY cloud, density views, summary.json\n"
              "The tables are rewritten after every test, so an interrupted run keeps its results.",
              [](CLI::App &app) -> Runner {
                  auto args = std::make_shared<ExperimentArgs>();
                  app.add_option("file", args->file, "the experiment file (YAML)")->type_name("FILE")->required();
                  app.add_option("--out", args->out, "output folder (default out/<experiment name>)")->type_name("DIR");
                  app.add_option("--tests", args->tests, "run only these tests, e.g. --tests 1,5,9")
                      ->type_name("ID,ID...")
                      ->delimiter(',')
                      ->allow_extra_args(false);
                  app.add_flag("--check", args->check, "validate the file and stop");
                  app.add_flag("--quiet", args->quiet, "no progress display");
                  app.add_flag("--report", args->report, "also write DIR/report.html (as `binocle report DIR`)");
                  return [args] { return experiment(*args); };
              }}};

} // namespace
} // namespace binocle::cli
