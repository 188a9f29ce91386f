// SPDX-License-Identifier: MIT
// `binocle experiment FILE`: runs the tests of an experiment (METHOD.md E1, E2).
#include "cli/command.hpp"
#include "core/error.hpp"
#include "experiment/experiment.hpp"
#include "report/html_report.hpp"

#include <iostream>
#include <sstream>

namespace binocle::cli {
namespace {

int run(const Args &args) {
    if (args.positional().size() != 1) throw Error("expected one experiment file: binocle experiment FILE (see --help)");
    PluginHost host;
    host.scan();
    // Everything is checked before the first test runs.
    Experiment e = loadExperiment(args.positional()[0], host);
    ExperimentOptions options;
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
    if (args.has("--report")) std::cerr << "report: " << report::writeExperimentReport(options.out_dir) << "\n";
    return failed ? 1 : 0;
}

Register reg({"experiment", "run an experiment (E1, E2 of METHOD.md): a table of errors and efficiencies, charts",
              "usage: binocle experiment FILE [--out DIR] [--tests ID,ID...] [--check] [--report] [--quiet]\n\n"
              "Runs each test of the experiment file: the base rig with the test's baseline,\n"
              "focal length, range, camera height and inclination. The whole file, and the rig\n"
              "of every test, is validated before anything runs. Writes into DIR (default\n"
              "out/<experiment name>):\n"
              "  results.csv, results.json   a row per test: B, f, R, FF, εx, εy, εz, η2D, η3D,\n"
              "                              valid-pixel ratio, time, and every evaluator figure\n"
              "  eta_3d_bars.png/.svg, eta_2d_bars.png/.svg, eta_3d_vs_ff.png/.svg   charts\n"
              "  test_<id>/                  disparity, PLY cloud, density views, summary.json\n"
              "The tables are rewritten after every test, so an interrupted run keeps its results.\n\n"
              "  --out DIR        output folder\n"
              "  --tests 1,5,9    run only these tests\n"
              "  --check          validate the file and stop\n"
              "  --report         also write DIR/report.html (as `binocle report DIR`)\n"
              "  --quiet          no progress bar\n",
              {"--check", "--quiet", "--report"},
              run});

} // namespace
} // namespace binocle::cli
