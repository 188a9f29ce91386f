// SPDX-License-Identifier: MIT
// The charts of an experiment (bars grouped like the paper's Fig. 6-7, scatter against
// FF), drawn from its rows. Internal to framework/experiment.
#pragma once

#include "experiment/results.hpp"

#include <string>
#include <vector>

namespace binocle::experiment {

// Writes each chart of e.charts as <dir>/<file>.png and .svg; a chart whose metric no row
// reported is skipped with a warning.
void writeCharts(const std::string &dir, const Experiment &e, const std::vector<Row> &rows);

} // namespace binocle::experiment
