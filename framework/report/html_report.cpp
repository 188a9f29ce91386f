// SPDX-License-Identifier: MIT
// The HTML report of an experiment, built from its output folder.
#include "report/html_report.hpp"

#include "core/error.hpp"
#include "files/atomic_file.hpp"
#include "input/names.hpp"
#include "input/utf8.hpp"
#include "report/chart.hpp"
#include "report/web_files.hpp"

#include <binocle/text.hpp>

#include <boost/beast/core/detail/base64.hpp>
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

namespace fs = std::filesystem;

namespace binocle::report {

namespace {

using OJson = nlohmann::ordered_json;

std::string escape(const std::string &s) { return input::xmlEscape(s); }

std::string readFile(const fs::path &p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream os;
    os << in.rdbuf();
    return os.str();
}

std::string dataUri(const std::string &bytes, const std::string &mime) {
    std::string out(boost::beast::detail::base64::encoded_size(bytes.size()), '\0');
    out.resize(boost::beast::detail::base64::encode(out.data(), bytes.data(), bytes.size()));
    return "data:" + mime + ";base64," + out;
}

std::string number(const OJson &v, int decimals = -1) {
    if (!v.is_number()) return "";
    const double d = v.get<double>();
    if (!std::isfinite(d)) return "";
    char buf[48];
    if (decimals >= 0) std::snprintf(buf, sizeof buf, "%.*f", decimals, d);
    else std::snprintf(buf, sizeof buf, "%.6g", d);
    return buf;
}

// The first file in `dir` whose name starts with `prefix` and ends with `suffix`
// (frames are numbered; the first frame stands for the test).
std::optional<fs::path> firstFile(const fs::path &dir, const std::string &prefix, const std::string &suffix) {
    std::vector<fs::path> found;
    std::error_code ec;
    for (const auto &e : fs::directory_iterator(dir, ec)) {
        const std::string n = e.path().filename().string();
        if (n.rfind(prefix, 0) == 0 && n.size() >= suffix.size() && n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0)
            found.push_back(e.path());
    }
    if (found.empty()) return std::nullopt;
    std::sort(found.begin(), found.end());
    return found.front();
}

struct Column {
    std::string key, label, unit;
    int decimals;
};

// The columns of the main table, in the words of METHOD.md.
const std::vector<Column> kMainColumns = {
    {"baseline_mm", "B", "mm", 0},          {"focal_length_mm", "f", "mm", 1},    {"range_mm", "R", "mm", 0},
    {"inclination_deg", "θ", "°", 1},        {"form_factor", "FF", "", 2},         {"epsilon_x_percent", "εx", "%", 1},
    {"epsilon_y_percent", "εy", "%", 1},    {"epsilon_z_percent", "εz", "%", 1},  {"eta_2d_percent", "η2D", "%", 1},
    {"eta_3d_percent", "η3D", "%", 1},      {"eta_3d_oracle_percent", "η3D oracle", "%", 1},
    {"valid_pixel_ratio", "valid px", "", 3}, {"seconds", "time", "s", 2}};

// What the paper reported, per test id and figure: results.json's `paper_reported`
// ({figure: {reported, measured, difference}}, written by the experiment from the
// file's `paper:` blocks) or its flat `paper_reported.<figure>` columns, else the
// experiment file's `paper:` blocks. (Columns named "paper.<figure>" are the `paper`
// evaluator's own figures, not the paper's.)
std::map<std::string, std::map<std::string, double>> paperValues(const OJson &results) {
    static const std::string kPrefix = "paper_reported.";
    std::map<std::string, std::map<std::string, double>> out;
    for (const auto &row : results["tests"]) {
        const std::string id = row.value("test", std::string());
        if (row.contains("paper_reported") && row["paper_reported"].is_object()) {
            for (const auto &[k, v] : row["paper_reported"].items())
                if (v.is_object() && v.contains("reported") && v["reported"].is_number()) out[id][k] = v["reported"].get<double>();
                else if (v.is_number()) out[id][k] = v.get<double>();
            continue;
        }
        for (const auto &[k, v] : row.items())
            if (k.compare(0, kPrefix.size(), kPrefix) == 0 && v.is_number()) out[id][k.substr(kPrefix.size())] = v.get<double>();
    }
    if (!out.empty()) return out;
    const std::string file = results.value("file", std::string());
    if (file.empty() || !fs::exists(file)) return out;
    try {
        const YAML::Node root = YAML::LoadFile(file);
        const YAML::Node tests = root["tests"];
        for (size_t i = 0; tests && tests.IsSequence() && i < tests.size(); ++i) {
            const YAML::Node t = tests[i];
            const std::string id = t["id"] ? t["id"].as<std::string>() : std::to_string(i + 1);
            if (const YAML::Node p = t["paper"]; p && p.IsMap())
                for (const auto &kv : p) {
                    double v = 0;
                    if (YAML::convert<double>::decode(kv.second, v)) out[id][kv.first.as<std::string>()] = v;
                }
        }
    } catch (const YAML::Exception &) {
        // The report still shows what was measured.
    }
    return out;
}

std::string cell(const OJson &row, const Column &c) {
    const OJson v = row.contains(c.key) ? row[c.key] : OJson();
    const std::string text = number(v, c.decimals);
    const std::string sort = number(v);
    return "<td class=\"num\" data-sort=\"" + (sort.empty() ? std::string("-1e300") : sort) + "\">" +
           (text.empty() ? std::string("<span class=\"na\">n/a</span>") : text) + "</td>";
}

std::string mainTable(const OJson &results, const std::map<std::string, std::map<std::string, double>> &paper) {
    // Paper columns only for the figures the experiment names.
    std::vector<std::string> paperKeys;
    for (const auto &[id, m] : paper)
        for (const auto &[k, v] : m)
            if (std::find(paperKeys.begin(), paperKeys.end(), k) == paperKeys.end()) paperKeys.push_back(k);
    std::ostringstream os;
    os << "<table class=\"sortable\" id=\"results\"><thead><tr><th data-type=\"num\">test</th><th>status</th>";
    for (const Column &c : kMainColumns) {
        os << "<th data-type=\"num\" title=\"" << escape(c.key) << "\">" << escape(c.label)
           << (c.unit.empty() ? "" : " <small>(" + escape(c.unit) + ")</small>") << "</th>";
        if (std::find(paperKeys.begin(), paperKeys.end(), c.key) != paperKeys.end())
            os << "<th data-type=\"num\" class=\"paper\" title=\"paper." << escape(c.key) << "\">" << escape(c.label)
               << " paper</th><th data-type=\"num\" class=\"paper\">Δ</th>";
    }
    os << "</tr></thead><tbody>";
    for (const auto &row : results["tests"]) {
        const std::string id = row.value("test", std::string());
        const std::string status = row.value("status", std::string());
        os << "<tr data-test=\"" << escape(id) << "\"><td class=\"num\" data-sort=\"" << escape(id) << "\"><a href=\"#test-"
           << escape(id) << "\">" << escape(id) << "</a></td><td class=\"" << (status == "ok" ? "ok" : "failed") << "\""
           << (row.contains("error") ? " title=\"" + escape(row["error"].get<std::string>()) + "\"" : "") << ">"
           << escape(status) << "</td>";
        for (const Column &c : kMainColumns) {
            os << cell(row, c);
            if (std::find(paperKeys.begin(), paperKeys.end(), c.key) == paperKeys.end()) continue;
            const auto t = paper.find(id);
            const bool have = t != paper.end() && t->second.count(c.key);
            if (!have) {
                os << "<td class=\"num paper\" data-sort=\"-1e300\"><span class=\"na\">–</span></td>"
                   << "<td class=\"num paper\" data-sort=\"-1e300\"></td>";
                continue;
            }
            const double reported = t->second.at(c.key);
            os << "<td class=\"num paper\" data-sort=\"" << reported << "\">" << number(OJson(reported), c.decimals) << "</td>";
            const OJson measured = row.contains(c.key) ? row[c.key] : OJson();
            if (measured.is_number()) {
                const double d = measured.get<double>() - reported;
                os << "<td class=\"num paper\" data-sort=\"" << d << "\">" << (d >= 0 ? "+" : "") << number(OJson(d), c.decimals)
                   << "</td>";
            } else {
                os << "<td class=\"num paper\" data-sort=\"-1e300\"></td>";
            }
        }
        os << "</tr>";
    }
    os << "</tbody></table>";
    return os.str();
}

// Every column results.json has, for the curious (collapsed).
std::string fullTable(const OJson &results) {
    std::vector<std::string> keys;
    for (const auto &row : results["tests"])
        for (const auto &[k, v] : row.items())
            if (k != "error" && std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k);
    std::ostringstream os;
    os << "<details><summary>All " << keys.size() << " columns of results.json</summary><div class=\"scroll\">"
       << "<table class=\"sortable\" id=\"all-columns\"><thead><tr>";
    for (const auto &k : keys) os << "<th data-type=\"" << (k == "status" ? "text" : "num") << "\">" << escape(k) << "</th>";
    os << "</tr></thead><tbody>";
    for (const auto &row : results["tests"]) {
        os << "<tr>";
        for (const auto &k : keys) {
            const OJson v = row.contains(k) ? row[k] : OJson();
            if (v.is_string()) os << "<td data-sort=\"" << escape(v.get<std::string>()) << "\">" << escape(v.get<std::string>()) << "</td>";
            else os << "<td class=\"num\" data-sort=\"" << (number(v).empty() ? "-1e300" : number(v)) << "\">" << number(v) << "</td>";
        }
        os << "</tr>";
    }
    os << "</tbody></table></div></details>";
    return os.str();
}

// Measured η3D beside the paper's, a pair of bars per test that names one.
std::string paperChart(const OJson &results, const std::map<std::string, std::map<std::string, double>> &paper) {
    BarChart c;
    c.title = "η3D measured and reported by the paper";
    c.y_label = "stereo efficiency η3D (%)";
    c.series = {"measured", "paper"};
    c.reference_lines = {70};
    for (const auto &row : results["tests"]) {
        const std::string id = row.value("test", std::string());
        const auto t = paper.find(id);
        if (t == paper.end() || !t->second.count("eta_3d_percent")) continue;
        const OJson m = row.contains("eta_3d_percent") ? row["eta_3d_percent"] : OJson();
        BarGroup g;
        g.label = "test " + id;
        g.values = {m.is_number() ? m.get<double>() : NAN, t->second.at("eta_3d_percent")};
        c.groups.push_back(std::move(g));
    }
    if (c.groups.empty()) return "";
    return "<figure class=\"chart\" id=\"chart-paper\">" + toSvg(c, 960, 420) + "<figcaption>" + escape(c.title) +
           "</figcaption></figure>";
}

std::string charts(const fs::path &dir) {
    std::vector<fs::path> svgs;
    std::error_code ec;
    for (const auto &e : fs::directory_iterator(dir, ec))
        if (e.path().extension() == ".svg") svgs.push_back(e.path());
    std::sort(svgs.begin(), svgs.end(), [](const fs::path &a, const fs::path &b) {
        // η3D against FF first: the paper's main figure.
        const bool fa = a.stem().string().find("_vs_") != std::string::npos, fb = b.stem().string().find("_vs_") != std::string::npos;
        return fa != fb ? fa : a < b;
    });
    std::ostringstream os;
    for (const auto &p : svgs) {
        std::string svg = readFile(p);
        // Inline SVG: the XML declaration, if any, does not belong inside HTML.
        if (svg.rfind("<?xml", 0) == 0) svg = svg.substr(svg.find("?>") + 2);
        os << "<figure class=\"chart\" id=\"chart-" << escape(p.stem().string()) << "\">" << svg << "<figcaption>"
           << escape(p.filename().string()) << "</figcaption></figure>";
    }
    return os.str();
}

// A PNG that is whole: its signature, and its last chunk IEND where the file ends (a
// copy or a write cut short loses the end first).
bool wholePng(const std::string &bytes) {
    static const std::string kSignature("\x89PNG\r\n\x1a\n", 8);
    static const std::string kEnd("IEND\xae\x42\x60\x82", 8);
    return bytes.size() >= kSignature.size() + 12 && bytes.compare(0, kSignature.size(), kSignature) == 0 &&
           bytes.compare(bytes.size() - kEnd.size(), kEnd.size(), kEnd) == 0;
}

// Images a test that ran should have and that the report could not show.
struct ImageProblems {
    std::vector<std::string> missing, unreadable; // "test_3: top view (XY)", "test_3/paper_top_000000.png"
};

// The value of the first column named "<evaluator>.<figure>" (whichever evaluator
// reported it), or null.
OJson figureOf(const OJson &row, const std::string &figure) {
    for (const auto &[k, v] : row.items())
        if (k.size() > figure.size() + 1 && k.compare(k.size() - figure.size() - 1, std::string::npos, "." + figure) == 0)
            return v;
    return OJson();
}

// What the reading took as the panel, in words beside the views that outline it.
std::string readingLine(const OJson &row) {
    const OJson x = figureOf(row, "measured_width_mm"), y = figureOf(row, "measured_range_mm"),
                z = figureOf(row, "measured_height_mm");
    if (x.is_null() && y.is_null() && z.is_null()) return "";
    auto metres = [](const OJson &v) { return v.is_number() ? number(OJson(v.get<double>() / 1000), 2) + " m" : std::string("–"); };
    std::ostringstream os;
    os << "<p class=\"reading\">Read as the panel (outlined in red in the front and top views): X′ = " << metres(x)
       << ", Y′ = " << metres(y) << ", Z′ = " << metres(z);
    const OJson xo = figureOf(row, "measured_width_oracle_mm");
    if (xo.is_number()) os << "; on the ground-truth disparity X′ = " << metres(xo);
    const OJson reg = figureOf(row, "registered");
    if (reg.is_number() && reg.get<double>() < 1)
        os << " · registered in " << number(OJson(100 * reg.get<double>()), 0) << " % of the frames";
    os << "</p>";
    return os.str();
}

std::string testSections(const fs::path &dir, const OJson &results, ImageProblems &problems) {
    std::ostringstream os;
    for (const auto &row : results["tests"]) {
        const std::string id = row.value("test", std::string());
        const fs::path t = dir / ("test_" + id);
        os << "<section class=\"test\" id=\"test-" << escape(id) << "\"><h3>Test " << escape(id) << "</h3><p class=\"facts\">";
        for (const Column &c : kMainColumns) {
            if (!row.contains(c.key) || !row[c.key].is_number()) continue;
            os << "<span>" << escape(c.label) << " = " << number(row[c.key], c.decimals) << (c.unit.empty() ? "" : " " + escape(c.unit))
               << "</span> ";
        }
        if (row.contains("error")) os << "<span class=\"failed\">" << escape(row["error"].get<std::string>()) << "</span>";
        os << "</p>" << readingLine(row) << "<div class=\"images\">";
        struct Item {
            const char *prefix, *label;
        };
        const Item items[] = {{"disparity_color_", "disparity"},
                              {"paper_top_", "top view (XY)"},
                              {"paper_front_", "front view (XZ)"},
                              {"paper_side_", "side view (YZ)"}};
        const bool ran = row.value("status", std::string("ok")) == "ok";
        for (const Item &item : items) {
            const auto file = firstFile(t, item.prefix, ".png");
            const std::string bytes = file ? readFile(*file) : std::string();
            os << "<figure>";
            if (file && wholePng(bytes)) {
                os << "<img alt=\"test " << escape(id) << " " << item.label << "\" src=\"" << dataUri(bytes, "image/png") << "\">";
            } else if (file) {
                const std::string name = t.filename().string() + "/" + file->filename().string();
                problems.unreadable.push_back(name);
                os << "<div class=\"missing\">" << escape(name) << " is truncated or not a PNG</div>";
            } else {
                if (ran) problems.missing.push_back(t.filename().string() + ": " + item.label);
                os << "<div class=\"missing\">no " << item.label << " image in " << escape(t.filename().string()) << "</div>";
            }
            os << "<figcaption>" << item.label << (file ? " · " + escape(file->filename().string()) : "") << "</figcaption></figure>";
        }
        os << "</div></section>";
    }
    return os.str();
}

// What makes results.json less than the whole experiment, in words; "" when complete
// (or written before binocle said: no `status`).
std::string incompleteness(const OJson &results) {
    const std::string status = results.value("status", std::string());
    const size_t rows = results["tests"].size();
    const size_t all = results.contains("test_ids") && results["test_ids"].is_array() ? results["test_ids"].size() : rows;
    std::string missing;
    if (results.contains("missing_tests") && results["missing_tests"].is_array())
        for (const auto &id : results["missing_tests"])
            if (id.is_string()) missing += (missing.empty() ? "" : ", ") + id.get<std::string>();
    if (status == "interrupted")
        return "the run stopped after " + std::to_string(rows) + " of " + std::to_string(all) + " tests (status: interrupted)";
    if (status == "partial")
        return std::to_string(rows) + " of " + std::to_string(all) + " tests (status: partial" +
               (missing.empty() ? std::string(", a share of the tests") : "; missing: " + missing) + ")";
    if (!status.empty() && status != "complete") return "status '" + status + "' is not one binocle writes";
    return "";
}

std::string provenance(const OJson &results) {
    std::ostringstream os;
    os << "<dl class=\"provenance\">";
    os << "<dt>experiment file</dt><dd>" << escape(results.value("file", std::string("?"))) << "</dd>";
    os << "<dt>base rig</dt><dd>" << escape(results.value("rig", std::string("?"))) << "</dd>";
    if (results.contains("software")) {
        const OJson &s = results["software"];
        os << "<dt>binocle</dt><dd>" << escape(s.value("binocle", std::string("?"))) << "</dd>";
        if (s.contains("plugins")) {
            os << "<dt>plugins</dt><dd>";
            bool first = true;
            for (const auto &p : s["plugins"]) {
                os << (first ? "" : ", ") << escape(p.value("name", std::string())) << " " << escape(p.value("version", std::string()))
                   << " <small>(" << escape(p.value("kind", std::string())) << ")</small>";
                first = false;
            }
            os << "</dd>";
        }
        if (s.contains("opencv")) os << "<dt>OpenCV</dt><dd>" << escape(s["opencv"].get<std::string>()) << "</dd>";
    } else {
        os << "<dt>software</dt><dd>not recorded in results.json (written by an older binocle)</dd>";
    }
    os << "</dl>";
    std::string rigYaml = results.value("rig_yaml", std::string());
    if (rigYaml.empty()) {
        const std::string rig = results.value("rig", std::string());
        if (!rig.empty() && fs::exists(rig)) rigYaml = readFile(rig);
    }
    if (!rigYaml.empty()) os << "<details><summary>The base rig</summary><pre>" << escape(rigYaml) << "</pre></details>";
    return os.str();
}

std::string fill(std::string text, const std::map<std::string, std::string> &values) {
    for (const auto &[k, v] : values) {
        const std::string mark = "{{" + k + "}}";
        for (size_t at = text.find(mark); at != std::string::npos; at = text.find(mark, at + v.size())) text.replace(at, mark.size(), v);
    }
    return text;
}

std::string embedded(const char *name) {
    const EmbeddedFile *f = webFile(name);
    if (!f) throw Error(std::string("report: the template file ") + name + " was not built into binocle");
    return f->text();
}

} // namespace

std::vector<std::string> experimentFolders(const std::string &dir) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw Error("report: " + dir + " is not a folder (expected the --out folder of binocle experiment)");
    if (fs::exists(fs::path(dir) / "results.json")) return {dir};
    std::vector<std::string> out;
    for (const auto &e : fs::directory_iterator(dir, ec))
        if (e.is_directory() && fs::exists(e.path() / "results.json")) out.push_back(e.path().string());
    std::sort(out.begin(), out.end());
    if (out.empty()) throw Error("report: " + dir + " holds no results.json, nor does any folder in it (run binocle experiment --out " + dir + " first)");
    return out;
}

namespace {
// The page of one experiment's results (below).
std::string reportHtml(const fs::path &dir, const std::string &dirText, const fs::path &resultsPath, const OJson &results);
} // namespace

std::string writeExperimentReport(const std::string &dirText, const std::string &outputText) {
    const fs::path dir(dirText);
    const fs::path resultsPath = dir / "results.json";
    if (!fs::exists(resultsPath)) throw Error("report: " + resultsPath.string() + " does not exist (run binocle experiment --out " + dirText + " first)");
    const OJson results = OJson::parse(readFile(resultsPath), nullptr, false);
    if (results.is_discarded() || !results.is_object() || !results.contains("tests") || !results["tests"].is_array())
        throw Error("report: " + resultsPath.string() + " is not the results.json of an experiment (no \"tests\" list)");
    // --output naming a folder (existing, or written with a final '/') gets report.html in
    // it, as `calibrate --out` does: a file is never renamed over a folder.
    std::error_code isDir;
    const bool intoFolder = !outputText.empty() && (outputText.back() == '/' || fs::is_directory(outputText, isDir));
    // Each row's test id names its folder test_<id>/, whose images are inlined: a file name,
    // never a path out of DIR.
    const auto &rows = results["tests"];
    for (size_t i = 0; i < rows.size(); ++i) {
        const OJson &row = rows[i];
        std::string why = "expected a text";
        if (!row.is_object() || !row.contains("test") || !row["test"].is_string() ||
            !input::isSafeName(row["test"].get<std::string>(), &why))
            throw Error("report: " + resultsPath.string() + ": tests[" + std::to_string(i) + "].test " +
                        (row.is_object() && row.contains("test") ? sdk::printable(row["test"].dump(), 60) : "(missing)") +
                        " is not valid: " + why + " (the id of a test, which names its folder test_<id>/)");
    }
    const std::string output = outputText.empty() ? (dir / "report.html").string()
                               : intoFolder       ? (fs::path(outputText) / "report.html").string()
                                                  : outputText;
    std::string html;
    try {
        html = reportHtml(dir, dirText, resultsPath, results);
    } catch (const OJson::exception &e) { // a value of another type than binocle experiment writes
        throw Error("report: " + resultsPath.string() + " is not the results.json of an experiment: " + e.what());
    }
    writeFileAtomic(output, html);
    return output;
}

namespace {

std::string reportHtml(const fs::path &dir, const std::string &dirText, const fs::path &resultsPath, const OJson &results) {
    const auto paper = paperValues(results);
    const std::string name = results.value("experiment", dir.filename().string());
    std::time_t written = std::time(nullptr);
    std::error_code ec;
    if (const auto t = fs::last_write_time(resultsPath, ec); !ec)
        written = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now() + (t - fs::file_time_type::clock::now()));
    char when[64];
    std::strftime(when, sizeof when, "%Y-%m-%d %H:%M UTC", std::gmtime(&written));
    size_t ok = 0;
    for (const auto &row : results["tests"]) ok += row.value("status", std::string()) == "ok";
    ImageProblems problems;
    const std::string tests = testSections(dir, results, problems);

    std::ostringstream summary;
    const std::string incomplete = incompleteness(results);
    if (!incomplete.empty()) summary << "INCOMPLETE: " << incomplete << " · ";
    summary << results["tests"].size() << " tests, " << ok << " ok · results of " << when;
    if (!paper.empty()) summary << " · the paper's values for " << paper.size() << " tests";
    if (!problems.missing.empty() || !problems.unreadable.empty())
        summary << " · images: " << problems.missing.size() << " missing, " << problems.unreadable.size() << " unreadable";
    if (!incomplete.empty()) spdlog::warn("report {}: incomplete results: {}", dirText, incomplete);
    for (const auto &m : problems.missing) spdlog::warn("report {}: no image for {}", dirText, m);
    for (const auto &u : problems.unreadable) spdlog::warn("report {}: {} is truncated or not a PNG: not shown", dirText, u);

    const std::string html = fill(embedded("report.html"), {{"TITLE", escape("Binocle experiment " + name)},
                                                            {"NAME", escape(name)},
                                                            {"DESCRIPTION", escape(results.value("description", std::string()))},
                                                            {"SUMMARY", escape(summary.str())},
                                                            {"STYLE", embedded("report.css")},
                                                            {"SCRIPT", embedded("report.js")},
                                                            {"TABLE", mainTable(results, paper)},
                                                            {"FULL_TABLE", fullTable(results)},
                                                            {"PAPER_CHART", paperChart(results, paper)},
                                                            {"CHARTS", charts(dir)},
                                                            {"TESTS", tests},
                                                            {"PROVENANCE", provenance(results)}});
    return html;
}

} // namespace

} // namespace binocle::report
