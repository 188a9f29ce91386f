// SPDX-License-Identifier: MIT
// The report of an experiment: one self-contained HTML file (images inlined as data URIs,
// style and script inline) that opens from disk with no server and no network.
#pragma once

#include <string>
#include <vector>

namespace binocle::report {

// Writes `output` (default: DIR/report.html) from what `binocle experiment` wrote into
// DIR (results.json, charts, test_<id>/): the sortable table, the charts, each test's
// disparity and density views, η3D against FF, the paper's values beside the measured
// ones where the experiment names them, the rig and the software versions. Returns the
// path written. Throws binocle::Error naming DIR when it holds no results.json.
std::string writeExperimentReport(const std::string &dir, const std::string &output = "");

// The experiment folders under `dir`: `dir` itself when it holds results.json, else its
// immediate subfolders that do (a demo's out/ holds several).
std::vector<std::string> experimentFolders(const std::string &dir);

} // namespace binocle::report
