// SPDX-License-Identifier: MIT
// Experiments: load and validate, run test by test, write tables and charts.
#include "experiment/experiment.hpp"

#include "config/rig_config.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/json.hpp"
#include "core/progress.hpp"
#include "method/design.hpp"
#include "pipeline/pipeline.hpp"
#include "report/chart.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <spdlog/spdlog.h>

namespace fs = std::filesystem;

namespace binocle {

namespace {

const std::vector<std::string> kVariables = {"baseline_mm", "focal_length_mm", "range_mm", "camera_height_mm",
                                             "inclination_deg"};
const std::vector<std::string> kTopKeys = {"name",     "description", "rig",   "frames", "lenses_mm", "baseline_range_mm",
                                           "pixel_pitch_um", "image_width_px", "bind", "defaults", "tests",   "charts"};
const std::vector<std::string> kTestKeys = {"id", "baseline_mm", "focal_length_mm", "range_mm", "camera_height_mm",
                                            "inclination_deg", "set"};

std::string join(const std::vector<std::string> &v) {
    std::string s;
    for (const auto &x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

std::string num(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

double *field(TestGeometry &g, const std::string &name) {
    if (name == "baseline_mm") return &g.baseline_mm;
    if (name == "focal_length_mm") return &g.focal_length_mm;
    if (name == "range_mm") return &g.range_mm;
    if (name == "camera_height_mm") return &g.camera_height_mm;
    if (name == "inclination_deg") return &g.inclination_deg;
    return nullptr;
}

struct Reader {
    std::string file;
    std::string where(const YAML::Node &n) const {
        if (!n.IsDefined() || n.Mark().is_null()) return file;
        return file + ":" + std::to_string(n.Mark().line + 1) + ":" + std::to_string(n.Mark().column + 1);
    }
    [[noreturn]] void fail(const YAML::Node &n, const std::string &what) const { throw Error(where(n) + ": " + what); }
    void checkKeys(const YAML::Node &map, const std::vector<std::string> &valid, const std::string &what) const {
        for (const auto &kv : map) {
            const std::string k = kv.first.as<std::string>();
            if (std::find(valid.begin(), valid.end(), k) != valid.end()) continue;
            const std::string hint = nearest(k, valid);
            fail(kv.first, what + ": unknown key '" + k + "'" + (hint.empty() ? "" : "; did you mean '" + hint + "'?") +
                               " (valid keys: " + join(valid) + ")");
        }
    }
    double number(const YAML::Node &n, const std::string &what) const {
        double v = 0;
        if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
            fail(n, what + ": value '" + (n.IsScalar() ? n.Scalar() : std::string("(not a scalar)")) + "' is not a number");
        return v;
    }
    std::vector<double> numbers(const YAML::Node &n, const std::string &what) const {
        if (!n.IsSequence()) fail(n, what + ": expected a list of numbers, e.g. [2.8, 4, 8]");
        std::vector<double> out;
        for (const auto &e : n) out.push_back(number(e, what));
        return out;
    }
};

// The rig paths a variable goes to, when the experiment does not say: the source's key
// of the same name, and the ground transform for height and inclination.
std::map<std::string, std::vector<std::string>> defaultBind(const YAML::Node &rig) {
    std::map<std::string, std::vector<std::string>> b;
    for (const auto &v : kVariables) b[v] = {"source." + v};
    if (YAML::Node t = rig["transforms"]; t && t.IsSequence())
        for (size_t i = 0; i < t.size(); ++i)
            if (t[i]["plugin"] && t[i]["plugin"].as<std::string>() == "ground") {
                b["camera_height_mm"].push_back("transforms." + std::to_string(i) + ".camera_height_mm");
                b["inclination_deg"].push_back("transforms." + std::to_string(i) + ".inclination_deg");
            }
    return b;
}

void checkGeometry(const Experiment &e, const ExperimentTest &t, const Reader &r, const YAML::Node &node) {
    const auto &g = t.geometry;
    const std::string who = "test " + t.id;
    if (!(g.range_mm > 0)) r.fail(node, who + ": range_mm = " + num(g.range_mm) + ": expected a positive range in mm");
    if (!(g.baseline_mm > 0)) r.fail(node, who + ": baseline_mm = " + num(g.baseline_mm) + ": expected a positive baseline in mm");
    if (!(g.focal_length_mm > 0))
        r.fail(node, who + ": focal_length_mm = " + num(g.focal_length_mm) + ": expected a positive focal length in mm");
    if (g.camera_height_mm < 0) r.fail(node, who + ": camera_height_mm = " + num(g.camera_height_mm) + ": expected >= 0");
    if (g.inclination_deg < -89 || g.inclination_deg > 89)
        r.fail(node, who + ": inclination_deg = " + num(g.inclination_deg) + ": expected -89 .. 89 degrees");
    if (!e.lenses_mm.empty() &&
        std::none_of(e.lenses_mm.begin(), e.lenses_mm.end(), [&](double f) { return std::fabs(f - g.focal_length_mm) < 1e-6; })) {
        std::vector<std::string> l;
        for (double f : e.lenses_mm) l.push_back(num(f));
        r.fail(node, who + ": focal_length_mm = " + num(g.focal_length_mm) + ": the rig has no such lens (lenses_mm: " + join(l) + ")");
    }
    if (e.baseline_max_mm > 0 && (g.baseline_mm < e.baseline_min_mm - 1e-9 || g.baseline_mm > e.baseline_max_mm + 1e-9))
        r.fail(node, who + ": baseline_mm = " + num(g.baseline_mm) + ": outside the rig's baseline range " + num(e.baseline_min_mm) +
                         " .. " + num(e.baseline_max_mm) + " mm");
}

std::string yamlBlock(const YAML::Node &n) {
    YAML::Emitter em;
    em << n;
    return em.c_str();
}

std::string yamlText(const YAML::Node &n) {
    YAML::Emitter em;
    em << YAML::Flow << n;
    return em.c_str();
}

} // namespace

YAML::Node rigForTest(const Experiment &e, const ExperimentTest &t) {
    YAML::Node rig = YAML::Clone(e.rig);
    TestGeometry g = t.geometry;
    for (const auto &[var, paths] : e.bind) {
        const double *v = field(g, var);
        if (!v) continue;
        for (const auto &p : paths) applyOverride(rig, Override{p, num(*v), "test " + t.id + ": " + p + "=" + num(*v)});
    }
    for (const auto &[path, value] : t.set) applyOverride(rig, Override{path, value, "test " + t.id + ": set " + path});
    return rig;
}

Experiment loadExperiment(const std::string &file, const PluginHost &host) {
    std::error_code ec;
    Experiment e;
    e.file = fs::absolute(file, ec).lexically_normal().string();
    if (!fs::exists(e.file)) throw Error("experiment file " + file + " does not exist");
    Reader r{e.file};
    YAML::Node root;
    try {
        root = YAML::LoadFile(e.file);
    } catch (const YAML::ParserException &x) {
        throw Error(e.file + ":" + std::to_string(x.mark.line + 1) + ":" + std::to_string(x.mark.column + 1) +
                    ": YAML syntax error: " + x.msg);
    }
    if (!root.IsMap()) throw Error(e.file + ": expected a map with rig:, tests: ...");
    r.checkKeys(root, kTopKeys, "experiment");
    e.name = root["name"] ? root["name"].as<std::string>() : fs::path(e.file).stem().string();
    e.description = root["description"] ? root["description"].as<std::string>() : "";
    if (!root["rig"] || !root["rig"].IsScalar()) throw Error(e.file + ": missing key 'rig' (the base rig file)");
    fs::path rigPath = root["rig"].Scalar();
    if (rigPath.is_relative()) rigPath = fs::path(e.file).parent_path() / rigPath;
    e.rig_file = rigPath.lexically_normal().string();
    if (!fs::exists(e.rig_file)) r.fail(root["rig"], "rig: file '" + e.rig_file + "' does not exist");
    try {
        e.rig = YAML::LoadFile(e.rig_file);
    } catch (const YAML::ParserException &x) {
        throw Error(e.rig_file + ":" + std::to_string(x.mark.line + 1) + ":" + std::to_string(x.mark.column + 1) +
                    ": YAML syntax error: " + x.msg);
    }
    if (root["frames"]) {
        const double f = r.number(root["frames"], "frames");
        if (f < 1 || f != std::floor(f)) r.fail(root["frames"], "frames: expected a whole number >= 1");
        e.frames = static_cast<int64_t>(f);
    }
    if (root["lenses_mm"]) e.lenses_mm = r.numbers(root["lenses_mm"], "lenses_mm");
    if (root["baseline_range_mm"]) {
        auto b = r.numbers(root["baseline_range_mm"], "baseline_range_mm");
        if (b.size() != 2 || !(b[0] > 0) || b[1] < b[0]) r.fail(root["baseline_range_mm"], "baseline_range_mm: expected [min, max] in mm");
        e.baseline_min_mm = b[0];
        e.baseline_max_mm = b[1];
    }
    if (root["pixel_pitch_um"]) e.pixel_pitch_um = r.number(root["pixel_pitch_um"], "pixel_pitch_um");
    else if (e.rig["source"] && e.rig["source"]["pixel_pitch_um"]) e.pixel_pitch_um = e.rig["source"]["pixel_pitch_um"].as<double>();
    else if (e.rig["source"] && e.rig["source"]["plugin"] && e.rig["source"]["plugin"].as<std::string>() == "sim")
        e.pixel_pitch_um = 20.8; // the sim's default: the Videre head's effective pixel
    if (root["image_width_px"]) e.image_width_px = static_cast<int>(r.number(root["image_width_px"], "image_width_px"));
    else if (e.rig["source"] && e.rig["source"]["image_width"]) e.image_width_px = e.rig["source"]["image_width"].as<int>();
    else if (e.pixel_pitch_um == 20.8) e.image_width_px = 320;

    e.bind = defaultBind(e.rig);
    if (YAML::Node b = root["bind"]) {
        if (!b.IsMap()) r.fail(b, "bind: expected a map variable -> list of rig paths");
        r.checkKeys(b, kVariables, "bind");
        for (const auto &kv : b) {
            std::vector<std::string> paths;
            if (kv.second.IsScalar()) paths.push_back(kv.second.Scalar());
            else if (kv.second.IsSequence())
                for (const auto &p : kv.second) paths.push_back(p.as<std::string>());
            else r.fail(kv.second, "bind." + kv.first.as<std::string>() + ": expected a rig path or a list of them");
            e.bind[kv.first.as<std::string>()] = paths;
        }
    }
    // Defaults of the variables: the experiment's `defaults:`, else the base rig's values.
    TestGeometry defaults;
    std::set<std::string> haveDefault;
    for (const auto &var : kVariables) {
        const auto &paths = e.bind[var];
        if (paths.empty()) continue;
        YAML::Node n = YAML::Clone(e.rig);
        bool found = true;
        std::stringstream ss(paths.front());
        for (std::string part; std::getline(ss, part, '.');) {
            if (!n.IsDefined() || n.IsNull() || n.IsScalar()) {
                found = false;
                break;
            }
            n = n.IsSequence() ? n[std::stoul(part)] : n[part];
        }
        double v = 0;
        if (found && n.IsDefined() && n.IsScalar() && YAML::convert<double>::decode(n, v)) {
            *field(defaults, var) = v;
            haveDefault.insert(var);
        }
    }
    if (YAML::Node d = root["defaults"]) {
        if (!d.IsMap()) r.fail(d, "defaults: expected a map of variables");
        r.checkKeys(d, kVariables, "defaults");
        for (const auto &kv : d) {
            *field(defaults, kv.first.as<std::string>()) = r.number(kv.second, "defaults." + kv.first.as<std::string>());
            haveDefault.insert(kv.first.as<std::string>());
        }
    }

    YAML::Node tests = root["tests"];
    if (!tests || !tests.IsSequence() || tests.size() == 0) throw Error(e.file + ": missing key 'tests' (a list of tests)");
    std::set<std::string> ids;
    for (size_t i = 0; i < tests.size(); ++i) {
        const YAML::Node tn = tests[i];
        if (!tn.IsMap()) r.fail(tn, "tests[" + std::to_string(i) + "]: expected a map (id, baseline_mm, focal_length_mm, range_mm, ...)");
        r.checkKeys(tn, kTestKeys, "tests[" + std::to_string(i) + "]");
        ExperimentTest t;
        t.id = tn["id"] ? tn["id"].as<std::string>() : std::to_string(i + 1);
        t.line = tn.Mark().line + 1;
        if (!ids.insert(t.id).second) r.fail(tn, "test " + t.id + ": id used twice");
        t.geometry = defaults;
        for (const auto &var : kVariables) {
            if (tn[var]) {
                *field(t.geometry, var) = r.number(tn[var], "test " + t.id + ": " + var);
            } else if (!haveDefault.count(var) && var != "inclination_deg" && var != "camera_height_mm") {
                r.fail(tn, "test " + t.id + ": no " + var + " (set it in the test, in defaults:, or in the base rig)");
            }
        }
        if (YAML::Node s = tn["set"]) {
            if (!s.IsMap()) r.fail(s, "test " + t.id + ": set: expected a map of rig paths to values");
            for (const auto &kv : s) t.set.emplace_back(kv.first.as<std::string>(), yamlText(kv.second));
        }
        checkGeometry(e, t, r, tn);
        // The whole rig of this test must be valid before anything runs.
        try {
            rigFromNode(rigForTest(e, t), e.rig_file, host);
        } catch (const Error &x) {
            r.fail(tn, "test " + t.id + ": its rig is invalid: " + x.what());
        }
        e.tests.push_back(std::move(t));
    }

    if (YAML::Node c = root["charts"]) {
        if (!c.IsSequence()) r.fail(c, "charts: expected a list");
        for (const auto &cn : c) {
            r.checkKeys(cn, {"type", "metric", "x", "title", "file", "reference_lines"}, "charts");
            ChartSpec s;
            s.type = cn["type"] ? cn["type"].as<std::string>() : "bars";
            if (s.type != "bars" && s.type != "scatter") r.fail(cn["type"], "charts: type '" + s.type + "': expected bars or scatter");
            if (!cn["metric"]) r.fail(cn, "charts: missing key 'metric' (e.g. eta_3d_percent)");
            s.metric = cn["metric"].as<std::string>();
            if (cn["x"]) s.x = cn["x"].as<std::string>();
            s.title = cn["title"] ? cn["title"].as<std::string>() : "";
            s.file = cn["file"] ? cn["file"].as<std::string>() : s.metric + (s.type == "scatter" ? "_vs_" + s.x : "");
            if (cn["reference_lines"]) s.reference_lines = r.numbers(cn["reference_lines"], "charts.reference_lines");
            e.charts.push_back(s);
        }
    } else {
        e.charts = {{"bars", "eta_3d_percent", "", e.name + ": stereo efficiency η3D per test", "eta_3d_bars", {70}},
                    {"bars", "eta_2d_percent", "", e.name + ": planar efficiency η2D per test", "eta_2d_bars", {70}},
                    {"scatter", "eta_3d_percent", "form_factor", e.name + ": η3D against the form factor FF", "eta_3d_vs_ff", {}}};
    }
    return e;
}

Experiment makeExperiment(const std::string &name, const std::string &rig_file, const std::vector<TestGeometry> &tests,
                          const PluginHost &host) {
    Experiment e;
    std::error_code ec;
    e.name = name;
    e.file = "(" + name + ")";
    e.rig_file = fs::absolute(rig_file, ec).lexically_normal().string();
    if (!fs::exists(e.rig_file)) throw Error("rig file " + rig_file + " does not exist");
    try {
        e.rig = YAML::LoadFile(e.rig_file);
    } catch (const YAML::Exception &x) {
        throw Error(e.rig_file + ": cannot read YAML: " + x.msg);
    }
    e.bind = defaultBind(e.rig);
    for (size_t i = 0; i < tests.size(); ++i) {
        ExperimentTest t;
        t.id = std::to_string(i + 1);
        t.geometry = tests[i];
        rigFromNode(rigForTest(e, t), e.rig_file, host); // throws with the reason
        e.tests.push_back(t);
    }
    e.charts = {{"scatter", "eta_3d_percent", "form_factor", name + ": η3D against the form factor FF", "eta_3d_vs_ff", {}}};
    return e;
}

namespace {

// Main columns first (the names of METHOD.md), then every other figure an evaluator
// reported, as "<evaluator>.<metric>".
const std::vector<std::string> kMainMetrics = {"epsilon_x_percent", "epsilon_y_percent", "epsilon_z_percent",
                                               "eta_2d_percent", "eta_3d_percent"};

using Row = ExperimentRow;

std::string csvCell(double v) {
    if (!std::isfinite(v)) return "";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

std::string testLabel(const ExperimentTest &t) {
    std::ostringstream os;
    os << "test " << t.id << " (R " << t.geometry.range_mm / 1000 << " m, B " << t.geometry.baseline_mm << " mm, f "
       << t.geometry.focal_length_mm << " mm";
    if (t.geometry.inclination_deg != 0) os << ", θ " << t.geometry.inclination_deg << "°";
    return os.str() + ")";
}

// What produced the results, for the report: binocle's and each plugin's version.
Json software(const PluginHost &host) {
    Json plugins = Json::array();
    for (const auto &p : host.plugins()) plugins.push_back({{"name", p.name}, {"version", p.version}, {"kind", kindName(p.kind)}});
    return {{"binocle", BINOCLE_VERSION}, {"opencv", CV_VERSION}, {"plugins", std::move(plugins)}};
}

void writeTables(const std::string &dir, const Experiment &e, const std::vector<Row> &rows, const PluginHost &host) {
    std::vector<std::string> columns;
    for (const auto &r : rows)
        for (const auto &[n, v] : r.values)
            if (std::find(columns.begin(), columns.end(), n) == columns.end()) columns.push_back(n);
    std::string csv = "test,status";
    for (const auto &c : columns) csv += "," + c;
    csv += ",error\n";
    Json tests = Json::array();
    for (const auto &r : rows) {
        csv += r.test_id + "," + r.status;
        Json row = {{"test", r.test_id}, {"status", r.status}};
        for (const auto &c : columns) {
            const double v = r.get(c);
            csv += "," + csvCell(v);
            row[c] = std::isfinite(v) ? Json(v) : Json(nullptr);
        }
        std::string err = r.error;
        std::replace(err.begin(), err.end(), '"', '\'');
        csv += ",\"" + err + "\"\n";
        if (!r.error.empty()) row["error"] = r.error;
        tests.push_back(std::move(row));
    }
    writeFileAtomic((fs::path(dir) / "results.csv").string(), csv);
    Json doc = {{"experiment", e.name},
                {"description", e.description},
                {"file", e.file},
                {"rig", e.rig_file},
                {"rig_yaml", yamlBlock(e.rig)},
                {"software", software(host)},
                {"units", {{"length", "mm"}, {"angle", "deg"}, {"errors_and_efficiencies", "%"}}},
                {"tests", std::move(tests)}};
    writeFileAtomic((fs::path(dir) / "results.json").string(), dumpJson(doc));
}

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

void writeCharts(const std::string &dir, const Experiment &e, const std::vector<Row> &rows) {
    for (const auto &spec : e.charts) {
        const bool any = std::any_of(rows.begin(), rows.end(), [&](const Row &r) { return std::isfinite(r.get(spec.metric)); });
        if (!any) {
            spdlog::warn("experiment: chart '{}' skipped: no test reported {}", spec.file, spec.metric);
            continue;
        }
        const std::string stem = (fs::path(dir) / spec.file).string();
        if (spec.type == "bars") {
            // Grouped like the paper's Fig. 6 and 7: a group per (range, baseline[, tilt]),
            // a bar per lens.
            BarChart c;
            c.title = spec.title.empty() ? spec.metric : spec.title;
            c.y_label = axisLabel(spec.metric);
            c.reference_lines = spec.reference_lines;
            std::vector<double> lenses;
            for (const auto &r : rows)
                if (std::find(lenses.begin(), lenses.end(), r.geometry.focal_length_mm) == lenses.end())
                    lenses.push_back(r.geometry.focal_length_mm);
            std::sort(lenses.begin(), lenses.end());
            for (double f : lenses) c.series.push_back("f = " + mm(f));
            for (const auto &r : rows) {
                const auto &g = r.geometry;
                std::string label = "R " + num(g.range_mm / 1000) + " m, B " + mm(g.baseline_mm);
                if (g.inclination_deg != 0) label += ", θ " + num(g.inclination_deg) + "°";
                auto it = std::find_if(c.groups.begin(), c.groups.end(), [&](const BarGroup &b) { return b.label == label; });
                if (it == c.groups.end()) {
                    c.groups.push_back({label, std::vector<double>(lenses.size(), NAN)});
                    it = c.groups.end() - 1;
                }
                const size_t s = std::find(lenses.begin(), lenses.end(), g.focal_length_mm) - lenses.begin();
                it->values[s] = r.get(spec.metric);
            }
            writeChart(stem, c);
        } else {
            ScatterChart c;
            c.title = spec.title.empty() ? spec.metric + " against " + spec.x : spec.title;
            c.x_label = axisLabel(spec.x);
            c.y_label = axisLabel(spec.metric);
            if (spec.x == "form_factor") {
                c.band_min = 1.2; // the paper's best FF band
                c.band_max = 2.0;
            }
            std::vector<double> ranges;
            for (const auto &r : rows) {
                const double R = r.geometry.range_mm;
                if (std::find(ranges.begin(), ranges.end(), R) == ranges.end()) ranges.push_back(R);
            }
            for (double R : ranges) c.series.push_back("R = " + num(R / 1000) + " m");
            for (const auto &r : rows) {
                const int s = static_cast<int>(std::find(ranges.begin(), ranges.end(), r.geometry.range_mm) - ranges.begin());
                c.points.push_back({r.get(spec.x), r.get(spec.metric), r.test_id, s});
            }
            writeChart(stem, c);
        }
    }
}

} // namespace

double ExperimentRow::get(const std::string &column) const {
    for (const auto &[n, v] : values)
        if (n == column) return v;
    return NAN;
}

void ExperimentRow::put(const std::string &column, double value) {
    for (auto &[n, x] : values)
        if (n == column) {
            x = value;
            return;
        }
    values.emplace_back(column, value);
}

ExperimentResult runExperiment(const Experiment &e, const PluginHost &host, const ExperimentOptions &options) {
    if (options.out_dir.empty()) throw Error("experiment: an output folder is needed (--out DIR)");
    std::error_code ec;
    fs::create_directories(options.out_dir, ec);
    if (ec) throw Error("--out " + options.out_dir + ": cannot create the folder: " + ec.message());
    std::vector<const ExperimentTest *> selected;
    for (const auto &t : e.tests)
        if (options.only.empty() || std::find(options.only.begin(), options.only.end(), t.id) != options.only.end())
            selected.push_back(&t);
    if (selected.empty()) throw Error("experiment " + e.file + ": no test selected (ids: " + join(options.only) + ")");

    std::vector<Row> rows;
    Progress progress(options.progress, "test", static_cast<int64_t>(selected.size()));
    const auto start = std::chrono::steady_clock::now();
    for (size_t i = 0; i < selected.size(); ++i) {
        const ExperimentTest &t = *selected[i];
        progress.update(static_cast<int64_t>(i), testLabel(t));
        Row row;
        row.test_id = t.id;
        row.geometry = t.geometry;
        const auto &g = t.geometry;
        row.put("baseline_mm", g.baseline_mm);
        row.put("focal_length_mm", g.focal_length_mm);
        row.put("range_mm", g.range_mm);
        row.put("camera_height_mm", g.camera_height_mm);
        row.put("inclination_deg", g.inclination_deg);
        row.put("form_factor", method::formFactor(g.baseline_mm, g.focal_length_mm, g.range_mm)); // Eq. 7
        if (e.pixel_pitch_um > 0) {
            method::StereoDesign d;
            d.baseline_mm = g.baseline_mm;
            d.focal_length_mm = g.focal_length_mm;
            d.pixel_pitch_um = e.pixel_pitch_um;
            d.image_width_px = e.image_width_px;
            d.camera_height_mm = g.camera_height_mm;
            d.inclination_deg = g.inclination_deg;
            const method::DesignFigures f = method::designFigures(d, g.range_mm);
            row.put("expected_disparity_px", f.disparity_px);
            row.put("depth_resolution_mm", f.depth_resolution_mm);
            row.put("stereo_field_width_mm", f.stereo_field_width_mm);
        }
        for (const auto &k : kMainMetrics) row.put(k, NAN);
        row.put("valid_pixel_ratio", NAN);
        row.put("seconds", NAN);
        const auto t0 = std::chrono::steady_clock::now();
        try {
            RigConfig rig = rigFromNode(rigForTest(e, t), e.rig_file, host);
            Pipeline pipeline(rig, host);
            RunOptions run;
            run.max_frames = e.frames;
            run.out_dir = (fs::path(options.out_dir) / ("test_" + t.id)).string();
            run.progress = false;
            std::vector<std::pair<std::string, double>> sums;
            std::vector<int> counts;
            double valid = 0;
            int frames = 0;
            pipeline.run(run, [&](const FrameResult &fr) {
                ++frames;
                valid += fr.valid_pixel_ratio;
                for (const auto &[name, value] : fr.figures) {
                    auto it = std::find_if(sums.begin(), sums.end(), [&](const auto &p) { return p.first == name; });
                    if (it == sums.end()) {
                        sums.emplace_back(name, 0.0);
                        counts.push_back(0);
                        it = sums.end() - 1;
                    }
                    if (std::isfinite(value)) {
                        it->second += value;
                        ++counts[it - sums.begin()];
                    }
                }
            });
            row.put("valid_pixel_ratio", frames ? valid / frames : NAN);
            for (size_t k = 0; k < sums.size(); ++k) {
                const double mean = counts[k] ? sums[k].second / counts[k] : NAN;
                const std::string &name = sums[k].first; // "<evaluator>.<metric>"
                const std::string metric = name.substr(name.find('.') + 1);
                if (std::find(kMainMetrics.begin(), kMainMetrics.end(), metric) != kMainMetrics.end() && !std::isfinite(row.get(metric)))
                    row.put(metric, mean);
                row.put(name, mean);
            }
        } catch (const std::exception &x) {
            row.status = "failed";
            row.error = x.what();
            spdlog::error("experiment: {} failed: {}", testLabel(t), x.what());
        }
        row.put("seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        rows.push_back(std::move(row));
        // Rewritten after every test: an interrupted experiment keeps what it measured.
        writeTables(options.out_dir, e, rows, host);
    }
    progress.update(static_cast<int64_t>(selected.size()), "done");
    progress.finish();
    writeCharts(options.out_dir, e, rows);
    ExperimentResult result;
    result.failed = std::count_if(rows.begin(), rows.end(), [](const Row &r) { return r.status != "ok"; });
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.rows = std::move(rows);
    return result;
}

} // namespace binocle
