// SPDX-License-Identifier: MIT
// The charts of an experiment: bars per test grouped by configuration, scatter against FF.
#include "experiment/charts.hpp"

#include "experiment/test_rig.hpp"
#include "method/design.hpp"
#include "report/chart.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <spdlog/spdlog.h>

namespace fs = std::filesystem;

namespace binocle::experiment {

namespace {

std::string mm(double v) { return num(v) + " mm"; }

// Axis labels in the words of METHOD.md for the figures it names.
std::string axisLabel(const std::string &metric) {
    static const std::pair<const char *, const char *> kNames[] = {
        {"eta_3d_percent", "stereo efficiency η3D (%)"}, {"eta_2d_percent", "planar efficiency η2D (%)"},
        {"epsilon_x_percent", "width error εx (%)"},     {"epsilon_y_percent", "range error εy (%)"},
        {"epsilon_z_percent", "height error εz (%)"},    {"form_factor", "form factor FF = 10·B·f/R (Eq. 7)"}};
    const std::string bare = metric.substr(metric.find('.') + 1);
    for (const auto &[k, v] : kNames)
        if (bare == k) return v;
    return metric;
}

} // namespace

void writeCharts(const std::string &dir, const Experiment &e, const std::vector<Row> &rows) {
    for (const auto &spec : e.charts) {
        const bool any = std::any_of(rows.begin(), rows.end(), [&](const Row &r) { return std::isfinite(r.get(spec.metric)); });
        if (!any) {
            spdlog::warn("experiment: chart '{}' skipped: no test reported {}", spec.file, spec.metric);
            continue;
        }
        const std::string stem = (fs::path(dir) / spec.file).string();
        const std::string lowKey = spec.metric + "_ci95_low", highKey = spec.metric + "_ci95_high";
        if (spec.type == "bars") {
            // Grouped like the paper's Fig. 6 and 7: a group per (range, baseline[, tilt]),
            // a bar per lens; error bars: the 95 % CI of the repeats; diamonds: the paper.
            BarChart c;
            c.title = spec.title.empty() ? spec.metric : spec.title;
            c.y_label = axisLabel(spec.metric);
            c.reference_lines = spec.reference_lines;
            c.reference_label = "paper";
            std::vector<double> lenses;
            for (const auto &r : rows)
                if (std::find(lenses.begin(), lenses.end(), r.test->geometry.focal_length_mm) == lenses.end())
                    lenses.push_back(r.test->geometry.focal_length_mm);
            std::sort(lenses.begin(), lenses.end());
            for (double f : lenses) c.series.push_back("f = " + mm(f));
            const bool withCi = std::any_of(rows.begin(), rows.end(), [&](const Row &r) { return std::isfinite(r.get(lowKey)); });
            if (withCi) c.title += " (mean, 95 % CI)";
            for (const auto &r : rows) {
                const auto &g = r.test->geometry;
                std::string label = "R " + num(g.range_mm / 1000) + " m, B " + mm(g.baseline_mm);
                if (g.inclination_deg != 0) label += ", θ " + num(g.inclination_deg) + "°";
                auto it = std::find_if(c.groups.begin(), c.groups.end(), [&](const BarGroup &b) { return b.label == label; });
                if (it == c.groups.end()) {
                    const std::vector<double> none(lenses.size(), NAN);
                    c.groups.push_back({label, none, none, none, none});
                    it = c.groups.end() - 1;
                }
                const size_t s = std::find(lenses.begin(), lenses.end(), g.focal_length_mm) - lenses.begin();
                it->values[s] = r.get(spec.metric);
                it->low[s] = r.get(lowKey);
                it->high[s] = r.get(highKey);
                for (const auto &[k, v] : r.test->paper)
                    if (k == spec.metric) it->reference[s] = v;
            }
            writeChart(stem, c);
        } else {
            ScatterChart c;
            c.title = spec.title.empty() ? spec.metric + " against " + spec.x : spec.title;
            c.x_label = axisLabel(spec.x);
            c.y_label = axisLabel(spec.metric);
            if (spec.x == "form_factor") {
                c.band_min = method::kBestFormFactorBand.min;
                c.band_max = method::kBestFormFactorBand.max;
            }
            std::vector<double> ranges;
            for (const auto &r : rows) {
                const double R = r.test->geometry.range_mm;
                if (std::find(ranges.begin(), ranges.end(), R) == ranges.end()) ranges.push_back(R);
            }
            for (double R : ranges) c.series.push_back("R = " + num(R / 1000) + " m");
            for (const auto &r : rows) {
                const int s = static_cast<int>(std::find(ranges.begin(), ranges.end(), r.test->geometry.range_mm) - ranges.begin());
                ScatterPoint pt{r.get(spec.x), r.get(spec.metric), r.test->id, s};
                pt.y_low = r.get(lowKey);
                pt.y_high = r.get(highKey);
                c.points.push_back(pt);
            }
            writeChart(stem, c);
        }
    }
}

} // namespace binocle::experiment
