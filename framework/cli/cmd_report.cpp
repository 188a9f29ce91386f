// SPDX-License-Identifier: MIT
// `binocle report DIR`: a self-contained HTML report of an experiment's results.
#include "cli/command.hpp"
#include "core/error.hpp"
#include "report/html_report.hpp"

#include <iostream>

namespace binocle::cli {
namespace {

int run(const Args &args) {
    if (args.positional().size() != 1) throw Error("expected one folder: binocle report DIR (see --help)");
    const std::vector<std::string> dirs = report::experimentFolders(args.positional()[0]);
    const std::string output = args.get("--output", "");
    if (!output.empty() && dirs.size() > 1)
        throw Error("--output " + output + ": " + args.positional()[0] + " holds " + std::to_string(dirs.size()) +
                    " experiments; without --output each gets DIR/<experiment>/report.html");
    for (const auto &dir : dirs) std::cout << report::writeExperimentReport(dir, output) << "\n";
    return 0;
}

Register reg({"report", "an experiment's results as one self-contained HTML file (table, charts, images)",
              "usage: binocle report DIR [--output FILE]\n\n"
              "Reads what `binocle experiment --out DIR` wrote (results.json, charts, test_<id>/)\n"
              "and writes DIR/report.html: the results table (sortable), the charts, η3D against\n"
              "the form factor, every test's disparity and top/front/side density views, the\n"
              "paper's values beside the measured ones where the experiment file names them\n"
              "(`paper:` per test), the rig and the software versions. Images are inlined: the\n"
              "file opens from disk with no server and no network. When DIR holds several\n"
              "experiment folders (e.g. out/demo), each gets its own report.\n\n"
              "  --output FILE    where to write (one experiment only; default DIR/report.html)\n",
              {},
              run});

} // namespace
} // namespace binocle::cli
