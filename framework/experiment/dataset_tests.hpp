// SPDX-License-Identifier: MIT
// Experiments over a dataset (`dataset:`, the benchmarks): a test per scene folder, a row
// per scene, then a row of the means; a bar per scene in each chart. Internal to
// framework/experiment.
#pragma once

#include "experiment/results.hpp"

#include <string>
#include <vector>

namespace binocle::experiment {

// The mean of each column over the ok rows (NaN where none has it), as test `mean`.
Row meanRow(const std::vector<Row> &rows, const ExperimentTest &mean);

// Each chart of e.charts as bars: one per row (the scenes, then the mean).
void writeSceneCharts(const std::string &dir, const Experiment &e, const std::vector<Row> &rows);

// After the last row (a run or a merge): over a dataset, the row of the means (as test
// `mean`, which must outlive the rows) and the scenes' charts; else the charts of charts.hpp.
void finishRows(const std::string &dir, const Experiment &e, std::vector<Row> &rows, const ExperimentTest &mean);

} // namespace binocle::experiment
