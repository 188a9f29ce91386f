// SPDX-License-Identifier: MIT
// results.csv and results.json of an experiment, and the rows they hold.
#include "experiment/results.hpp"

#include "experiment/test_rig.hpp"
#include "files/atomic_file.hpp"
#include "host/plugin_host.hpp"
#include "host/plugin_kinds.hpp"
#include "input/names.hpp"
#include "method/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include <opencv2/core/version.hpp>

namespace fs = std::filesystem;

namespace binocle {

namespace {

// A row's values are few and ordered: looked up by name, put in place or at the end.
using Values = std::vector<std::pair<std::string, double>>;

double valueIn(const Values &values, const std::string &k) {
    for (const auto &[n, v] : values)
        if (n == k) return v;
    return NAN;
}

void putIn(Values &values, const std::string &k, double v) {
    for (auto &[n, x] : values)
        if (n == k) {
            x = v;
            return;
        }
    values.emplace_back(k, v);
}

} // namespace

namespace experiment {

// eta_3d_oracle_percent: the same reading on the cloud of the ground-truth disparity, where
// an evaluator reports one (what the camera configuration alone allows, beside what the
// matcher's cloud gives).
const std::vector<std::string> kMainMetrics = {"epsilon_x_percent", "epsilon_y_percent", "epsilon_z_percent",
                                               "eta_2d_percent", "eta_3d_percent", "eta_3d_oracle_percent"};
const std::vector<std::string> kRepeatedMetrics = {"epsilon_x_percent", "epsilon_y_percent", "epsilon_z_percent",
                                                   "eta_2d_percent",    "eta_3d_percent",    "eta_3d_oracle_percent",
                                                   "valid_pixel_ratio"};

namespace {

// Row keys that are not numbers.
const std::vector<std::string> kRowTextKeys = {"test", "status", "error"};

std::string csvCell(double v) {
    if (!std::isfinite(v)) return "";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

// Spearman's rho between each predictor (a row column) and η3D over the rows that
// measured it; the best is the one with the highest rho.
OJson predictorRho(const std::vector<Row> &rows) {
    static const std::vector<std::pair<std::string, std::string>> kColumns = {
        {"form_factor", "form_factor"},
        {"ff_band", "predictor.ff_band"},
        {"expected_disparity", "expected_disparity_px"},
        {"depth_resolution", "predictor.depth_resolution"},
        {"sensor_aware", "predictor.sensor_aware"}};
    std::vector<double> eta;
    for (const auto &r : rows) eta.push_back(r.status == "ok" ? r.get("eta_3d_percent") : NAN);
    OJson rho = OJson::object();
    std::string best;
    double bestRho = -2;
    int n = 0;
    for (double v : eta) n += std::isfinite(v) ? 1 : 0;
    for (const auto &[name, column] : kColumns) {
        std::vector<double> x;
        for (const auto &r : rows) x.push_back(r.get(column));
        const double value = method::spearman(x, eta);
        rho[name] = std::isfinite(value) ? OJson(value) : OJson();
        if (std::isfinite(value) && value > bestRho) {
            bestRho = value;
            best = name;
        }
    }
    OJson out = OJson::object();
    out["against"] = "eta_3d_percent";
    out["tests"] = n;
    out["spearman_rho"] = rho;
    out["best"] = best.empty() ? OJson() : OJson(best);
    out["note"] = "each predictor as a score where higher should mean better: ff_band = -(log distance of FF from "
                  "1.2-2.0), depth_resolution = -dR/R, sensor_aware = eta_3d predicted from the design "
                  "(base/method/predictors.hpp)";
    return out;
}

// What produced the results, for the report: binocle's and each plugin's version.
// Only the plugins the rig names: the same list whichever others the host has opened.
OJson software(const PluginHost &host, const YAML::Node &rig) {
    std::set<std::string> named;
    auto add = [&](const YAML::Node &block) {
        if (block.IsMap() && block["plugin"] && block["plugin"].IsScalar()) named.insert(block["plugin"].Scalar());
    };
    for (const PluginKind *k : pluginKinds()) {
        const YAML::Node node = rig[k->rigKey];
        if (!node) continue; // a kind the rig leaves out (an invalid node: no IsMap())
        if (k->inRig != PluginKind::InRig::List) add(node);
        else if (node.IsSequence())
            for (const auto &b : node) add(b);
    }
    OJson plugins = OJson::array();
    for (const auto &name : named) { // sorted by name
        const PluginRecord *p = host.find(name);
        for (const auto &d : host.described()) // an isolated plugin is described, not opened
            if (!p && d.name == name) p = &d;
        if (p) plugins.push_back({{"name", p->name}, {"version", p->version}, {"kind", kindName(p->kind)}});
    }
    return {{"binocle", BINOCLE_VERSION}, {"opencv", CV_VERSION}, {"plugins", std::move(plugins)}};
}

} // namespace

double Row::get(const std::string &k) const { return valueIn(values, k); }

void Row::put(const std::string &k, double v) { putIn(values, k, v); }

OJson Row::toJson() const {
    OJson row = OJson::object();
    row["test"] = test->id;
    row["status"] = status;
    for (const auto &[n, v] : values) row[n] = std::isfinite(v) ? OJson(v) : OJson();
    if (!error.empty()) row["error"] = error;
    for (const auto &[k, v] : details.items()) row[k] = v;
    return row;
}

Row Row::fromJson(const OJson &j, const ExperimentTest *t) {
    Row r;
    r.test = t;
    r.status = j.value("status", "ok");
    r.error = j.value("error", "");
    for (const auto &[k, v] : j.items()) {
        if (std::find(kRowTextKeys.begin(), kRowTextKeys.end(), k) != kRowTextKeys.end()) continue;
        if (v.is_number()) r.values.emplace_back(k, v.get<double>());
        else if (v.is_null()) r.values.emplace_back(k, NAN);
        else r.details[k] = v;
    }
    return r;
}

void writeTables(const std::string &dir, const Experiment &e, const std::vector<Row> &rows, const TablesMeta &meta) {
    std::vector<std::string> columns;
    for (const auto &r : rows)
        for (const auto &[n, v] : r.values)
            if (std::find(columns.begin(), columns.end(), n) == columns.end()) columns.push_back(n);
    std::string csv = "test,status";
    for (const auto &c : columns) csv += "," + c;
    csv += ",error\n";
    OJson tests = OJson::array();
    for (const auto &r : rows) {
        csv += r.test->id + "," + r.status;
        for (const auto &c : columns) csv += "," + csvCell(r.get(c));
        std::string err = r.error;
        std::replace(err.begin(), err.end(), '"', '\'');
        csv += ",\"" + err + "\"\n";
        tests.push_back(r.toJson());
    }
    writeFileAtomic((fs::path(dir) / "results.csv").string(), csv);
    OJson doc = OJson::object();
    doc["experiment"] = e.name;
    doc["status"] = meta.status;
    doc["description"] = e.description;
    doc["file"] = e.file;
    doc["rig"] = e.rig_file;
    doc["rig_yaml"] = yamlBlock(e.rig);
    doc["software"] = meta.software;
    doc["overrides"] = e.overrides;
    doc["calibration"] = e.calibration;
    doc["test_ids"] = meta.test_ids;
    if (!meta.missing_tests.empty()) doc["missing_tests"] = meta.missing_tests;
    OJson charts = OJson::array();
    for (const auto &c : e.charts) charts.push_back(c.file);
    doc["charts"] = std::move(charts);
    if (meta.shard_count > 1) doc["shard"] = {{"index", meta.shard_index}, {"count", meta.shard_count}};
    doc["units"] = {{"length", "mm"}, {"angle", "deg"}, {"errors_and_efficiencies", "%"}};
    doc["statistics"] = "with repeats: each figure is the mean over repeats; <figure>_sd the sample standard deviation, "
                        "<figure>_ci95_low/_high the 95 % confidence interval of the mean (Student t, n - 1 degrees of "
                        "freedom); per-repeat values under per_repeat";
    doc["predictors"] = predictorRho(rows);
    doc["tests"] = std::move(tests);
    writeFileAtomic((fs::path(dir) / "results.json").string(), doc.dump(2) + "\n");
}

ExperimentResult resultOf(const std::vector<Row> &rows) {
    ExperimentResult result;
    for (const auto &r : rows) {
        ExperimentRow out;
        out.test_id = r.test->id;
        out.geometry = r.test->geometry;
        out.status = r.status;
        out.error = r.error;
        out.values = r.values;
        result.rows.push_back(std::move(out));
    }
    result.failed = std::count_if(rows.begin(), rows.end(), [](const Row &r) { return r.status != "ok"; });
    return result;
}

TablesMeta metaOf(const Experiment &e, int shardIndex, int shardCount, const PluginHost &host) {
    TablesMeta m;
    m.software = software(host, e.rig);
    for (const auto &t : e.tests) m.test_ids.push_back(t.id);
    m.shard_index = shardIndex;
    m.shard_count = shardCount;
    return m;
}

std::string resultsOwner(const std::string &dir) {
    std::error_code ec;
    const fs::path path = fs::path(dir) / "results.json";
    if (fs::file_size(path, ec) > (uint64_t{64} << 20) || ec) return "";
    std::ifstream in(path);
    const OJson doc = OJson::parse(in, nullptr, false);
    if (doc.is_discarded() || !doc.is_object() || !doc.contains("file") || !doc["file"].is_string()) return "";
    return doc["file"].get<std::string>();
}

void clearResults(const std::string &dir) {
    std::error_code ec;
    const fs::path base(dir);
    std::ifstream in(base / "results.json");
    const OJson doc = OJson::parse(in, nullptr, false);
    auto names = [&](const char *key) {
        std::vector<std::string> out;
        if (doc.is_object() && doc.contains(key) && doc[key].is_array())
            for (const auto &v : doc[key])
                if (v.is_string() && input::isSafeName(v.get<std::string>())) out.push_back(v.get<std::string>());
        return out;
    };
    for (const auto &id : names("test_ids")) fs::remove_all(base / ("test_" + id), ec); // a symlink: the link only
    for (const auto &stem : names("charts"))
        for (const char *ext : {".png", ".svg"}) fs::remove(base / (stem + ext), ec);
    for (const char *file : {"results.csv", "report.html", "results.json"}) fs::remove(base / file, ec);
}

} // namespace experiment

double ExperimentRow::get(const std::string &column) const { return valueIn(values, column); }

void ExperimentRow::put(const std::string &column, double value) { putIn(values, column, value); }

} // namespace binocle
