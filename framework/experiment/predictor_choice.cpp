// SPDX-License-Identifier: MIT
// Reads the predictors' rho from an experiment's results and picks the best.
#include "experiment/predictor_choice.hpp"

#include "core/error.hpp"
#include "method/predictors.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>

namespace binocle {

PredictorChoice loadPredictorChoice(const std::string &file) {
    std::ifstream in(file);
    if (!in) throw Error("predictors file " + file + " cannot be read");
    nlohmann::ordered_json doc;
    try {
        doc = nlohmann::ordered_json::parse(in);
    } catch (const nlohmann::json::exception &x) {
        throw Error(file + ": not valid JSON: " + x.what());
    }
    PredictorChoice c;
    c.file = file;
    if (doc.contains("experiment") && doc["experiment"].is_string()) c.experiment = doc["experiment"].get<std::string>();
    const nlohmann::ordered_json &p = doc.contains("predictors") ? doc["predictors"] : doc;
    if (!p.is_object() || !p.contains("spearman_rho") || !p["spearman_rho"].is_object())
        throw Error(file + ": no predictors.spearman_rho (expected the results.json of `binocle experiment`)");
    c.tests = p.value("tests", 0);
    const auto &names = method::predictorNames();
    double best = -2;
    for (const auto &[name, value] : p["spearman_rho"].items()) {
        if (std::find(names.begin(), names.end(), name) == names.end())
            throw Error(file + ": predictors.spearman_rho: unknown predictor '" + name + "'");
        const double rho = value.is_number() ? value.get<double>() : NAN;
        c.rho.emplace_back(name, rho);
        if (std::isfinite(rho) && rho > best) {
            best = rho;
            c.best = name;
        }
    }
    if (c.best.empty()) throw Error(file + ": predictors.spearman_rho: no predictor has a measured rho");
    return c;
}

} // namespace binocle
