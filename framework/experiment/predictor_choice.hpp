// SPDX-License-Identifier: MIT
// Which predictor `binocle design` ranks with: the one whose Spearman rho with measured
// η3D is highest in an experiment's results.json (by default the simulated E1's,
// configs/predictors/e1-sim.json).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace binocle {

struct PredictorChoice {
    std::string file;                                  // where the rho values came from
    std::string experiment;                            // its experiment, when it names one
    int tests = 0;                                     // tests the rho values were measured over
    std::vector<std::pair<std::string, double>> rho;   // predictor -> rho, in the file's order (NaN: not measured)
    std::string best;                                  // highest rho; the first of equals
};

// Reads the `predictors` block of a results.json (or of a file holding only that block).
// Throws binocle::Error naming the file and what is missing; an unknown predictor name
// is an error too (method::predictorNames()).
PredictorChoice loadPredictorChoice(const std::string &file);

} // namespace binocle
