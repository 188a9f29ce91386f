// SPDX-License-Identifier: MIT
// `binocle report DIR`: a self-contained HTML report of an experiment's results.
#include "app/report.hpp"
#include "cli/command.hpp"

#include <iostream>

namespace binocle::cli {
namespace {

int report(const app::ReportRequest &request) {
    app::writeReports(request, [](const std::string &path) { std::cout << path << "\n"; });
    return 0;
}

Register reportCommand{{"report", "an experiment's results as one self-contained HTML file (table, charts, images)",
              "Reads what `binocle experiment --out DIR` wrote (results.json, charts, test_<id>/)\n"
              "and writes DIR/report.html: the results table (sortable), the charts, η3D against\n"
              "the form factor, every test's disparity and top/front/side density views, the\n"
              "paper's values beside the measured ones where the experiment file names them\n"
              "(`paper:` per test), the rig and the software versions. Images are inlined: the\n"
              "file opens from disk with no server and no network. When DIR holds several\n"
              "experiment folders (e.g. out/demo), each gets its own report.",
              define<app::ReportRequest>(
                  [](CLI::App &app, app::ReportRequest &args) {
                      app.add_option("dir", args.dir, "the experiment's output folder")->type_name("DIR")->required();
                      app.add_option("--output", args.output, "the report's file (one experiment only; default DIR/report.html; not a folder)")
                          ->type_name("FILE");
                  },
                  report)}};

} // namespace
} // namespace binocle::cli
