// SPDX-License-Identifier: MIT
// writeReports(): the output's checks and the lock of each experiment folder reported on.
#include "app/report.hpp"

#include "core/output_folder.hpp"
#include "report/html_report.hpp"

#include <filesystem>
#include <optional>

namespace binocle::app {

std::vector<std::string> writeReports(const ReportRequest &request, const std::function<void(const std::string &path)> &written) {
    const Caller &caller = request.caller;
    const std::string &output = request.output;
    // The path whole (not cut like a value shown by Caller::shown): it names a file.
    const std::string named = caller.arg("output") + " " + output;
    // The output names the report's file: never a folder, whose other files a report would
    // sit among (and an existing report.html in it would be replaced).
    std::error_code ec;
    if (!output.empty() && (output.back() == '/' || std::filesystem::is_directory(output, ec)))
        throw RequestError(named + ": is a folder; expected the report's file name (e.g. " +
                           (std::filesystem::path(output) / "report.html").string() + ")");
    const std::vector<std::string> dirs = report::experimentFolders(request.dir);
    if (!output.empty() && dirs.size() > 1)
        throw RequestError(named + ": " + request.dir + " holds " + std::to_string(dirs.size()) +
                           " experiments; without " + caller.arg("output") + " each gets DIR/<experiment>/report.html");
    std::vector<std::string> paths;
    for (const auto &dir : dirs) {
        // A lock only (no kind): not into a folder an experiment still writes.
        std::optional<OutputFolder> folder;
        if (output.empty()) folder.emplace(dir, caller.claim(OutputKind::None, false));
        paths.push_back(report::writeExperimentReport(dir, output));
        if (written) written(paths.back());
    }
    return paths;
}

} // namespace binocle::app
