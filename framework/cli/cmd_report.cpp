// SPDX-License-Identifier: MIT
// `binocle report DIR`: a self-contained HTML report of an experiment's results.
#include "cli/command.hpp"
#include "core/output_folder.hpp"
#include "report/html_report.hpp"

#include <filesystem>
#include <iostream>
#include <optional>

namespace binocle::cli {
namespace {

struct ReportArgs {
    std::string dir, output;
};

int report(const ReportArgs &args) {
    // --output names the report's file: never a folder, whose other files a report would
    // sit among (and an existing report.html in it would be replaced).
    std::error_code ec;
    if (!args.output.empty() && (args.output.back() == '/' || std::filesystem::is_directory(args.output, ec)))
        throw UsageError("--output " + args.output + ": is a folder; expected the report's file name (e.g. " +
                         (std::filesystem::path(args.output) / "report.html").string() + ")");
    const std::vector<std::string> dirs = report::experimentFolders(args.dir);
    if (!args.output.empty() && dirs.size() > 1)
        throw UsageError("--output " + args.output + ": " + args.dir + " holds " + std::to_string(dirs.size()) +
                         " experiments; without --output each gets DIR/<experiment>/report.html");
    for (const auto &dir : dirs) {
        // Not into a folder an experiment still writes: its tables would be half done.
        std::optional<OutputFolder> folder;
        if (args.output.empty()) folder.emplace(dir, OutputClaim{OutputKind::None, false, "binocle report"});
        std::cout << report::writeExperimentReport(dir, args.output) << "\n";
    }
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
              define<ReportArgs>(
                  [](CLI::App &app, ReportArgs &args) {
                      app.add_option("dir", args.dir, "the experiment's output folder")->type_name("DIR")->required();
                      app.add_option("--output", args.output, "the report's file (one experiment only; default DIR/report.html; not a folder)")
                          ->type_name("FILE");
                  },
                  report)}};

} // namespace
} // namespace binocle::cli
