// SPDX-License-Identifier: MIT
// Experiments over a dataset (`dataset:`, the benchmarks): a row per scene, then the
// means; a bar chart per metric, one bar per scene and one for the mean.
#include "experiment/dataset_tests.hpp"

#include "experiment/charts.hpp"

#include "report/chart.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <spdlog/spdlog.h>

namespace fs = std::filesystem;

namespace binocle::experiment {

Row meanRow(const std::vector<Row> &rows, const ExperimentTest &mean) {
    Row out;
    out.test = &mean;
    std::vector<std::string> seen;
    for (const auto &r : rows)
        for (const auto &[name, value] : r.values) {
            (void)value;
            if (std::find(seen.begin(), seen.end(), name) != seen.end()) continue;
            seen.push_back(name);
            double sum = 0;
            int n = 0;
            for (const auto &s : rows)
                if (s.status == "ok" && std::isfinite(s.get(name))) sum += s.get(name), ++n;
            out.put(name, n ? sum / n : NAN);
        }
    out.details["mean_of"] = rows.size();
    return out;
}

void writeSceneCharts(const std::string &dir, const Experiment &e, const std::vector<Row> &rows) {
    for (const auto &spec : e.charts) {
        BarChart c;
        c.title = spec.title.empty() ? e.name + ": " + spec.metric : spec.title;
        c.y_label = spec.metric;
        const YAML::Node matcher = e.rig["matcher"]; // the legend: the matcher the rig runs
        c.series = {matcher.IsMap() && matcher["plugin"].IsScalar() ? matcher["plugin"].Scalar() : e.name};
        c.reference_lines = spec.reference_lines;
        double most = 0;
        for (const auto &r : rows) {
            const double v = r.get(spec.metric);
            c.groups.push_back({r.test->id, {v}, {}, {}, {NAN}});
            if (std::isfinite(v)) most = std::max(most, v);
        }
        if (most == 0 && std::none_of(rows.begin(), rows.end(), [&](const Row &r) { return std::isfinite(r.get(spec.metric)); })) {
            spdlog::warn("experiment: chart '{}' skipped: no scene reported {}", spec.file, spec.metric);
            continue;
        }
        const bool percent = spec.metric.size() > 8 && spec.metric.compare(spec.metric.size() - 8, 8, "_percent") == 0;
        // The axis fits the data (percentages in steps of 10, at most 100).
        c.y_max = percent ? std::min(100.0, std::max(10.0, 10 * std::ceil(most * 1.1 / 10))) : std::max(1.0, std::ceil(most * 1.1));
        writeChart((fs::path(dir) / spec.file).string(), c);
    }
}

void finishRows(const std::string &dir, const Experiment &e, std::vector<Row> &rows, const ExperimentTest &mean) {
    if (!e.dataset_tests) {
        writeCharts(dir, e, rows);
        return;
    }
    rows.push_back(meanRow(rows, mean));
    writeSceneCharts(dir, e, rows);
}

} // namespace binocle::experiment
