// SPDX-License-Identifier: MIT
// Reporting on experiments (`binocle report`): the report's file checked, each
// experiment folder locked while its report.html is written.
#pragma once

#include "app/request.hpp"

#include <functional>
#include <string>
#include <vector>

namespace binocle::app {

struct ReportRequest {
    Caller caller{"binocle report"};
    std::string dir;    // an experiment's folder, or a folder of them (a demo's out/)
    std::string output; // the report's file (one experiment only); empty: DIR/<experiment>/report.html
};

// Writes one HTML report per experiment folder under request.dir and returns the paths
// written, each also given to `written` (when set) as soon as it is. Refused as a
// RequestError before anything is written: an output that is a folder (whose other files
// the report would sit among), or one output for several experiments. Without an output,
// each report goes into its experiment's folder, locked while it is written (never into
// a folder an experiment still writes: its tables would be half done).
std::vector<std::string> writeReports(const ReportRequest &request,
                                      const std::function<void(const std::string &path)> &written = {});

} // namespace binocle::app
