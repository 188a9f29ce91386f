// SPDX-License-Identifier: MIT
// Experiments: load and validate, run test by test, write tables and charts.
#include "experiment/experiment.hpp"

#include "config/rig_config.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/progress.hpp"
#include "input/numbers.hpp"
#include "input/text.hpp"
#include "input/yaml_file.hpp"
#include "method/design.hpp"
#include "method/predictors.hpp"
#include "method/statistics.hpp"
#include "pipeline/pipeline.hpp"
#include "report/chart.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <set>
#include <sstream>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

namespace fs = std::filesystem;

namespace binocle {

namespace {

const std::vector<std::string> kVariables = {"baseline_mm", "focal_length_mm", "range_mm", "camera_height_mm",
                                             "inclination_deg"};
const std::vector<std::string> kTopKeys = {
    "name",    "description", "rig",        "frames",     "lenses_mm",         "baseline_range_mm", "pixel_pitch_um",
    "image_width_px", "image_height_px", "disparity_search_px", "bind", "defaults", "tests", "charts", "repeats",
    "seed",    "seeds",       "seed_path",  "jitter",     "calibration",       "board_calibration", "lens_table", "panel",
    "rig_set"};
const std::vector<std::string> kTestKeys = {"id", "baseline_mm", "focal_length_mm", "range_mm", "camera_height_mm",
                                            "inclination_deg", "set", "repeats", "paper"};

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
        if (!map.IsMap()) fail(map, what + ": expected a map");
        if (auto unknown = input::findUnknownKey(map, valid)) fail(unknown->key, what + ": " + unknown->message);
    }
    // One strict reader of numbers (input/numbers.hpp): decimal, finite.
    double number(const YAML::Node &n, const std::string &what) const {
        double v = 0;
        std::string why;
        if (!n.IsScalar() || !input::parseReal(n.Scalar(), v, &why))
            fail(n, what + ": value '" + (n.IsScalar() ? input::printable(n.Scalar()) : std::string("(not a scalar)")) +
                        "' is not valid: " + (why.empty() ? "expected a number" : why));
        return v;
    }
    // A whole number in [min, max], checked before the cast.
    int64_t integer(const YAML::Node &n, const std::string &what, int64_t min, int64_t max) const {
        const double v = number(n, what);
        if (!(v >= static_cast<double>(min) && v <= static_cast<double>(max)) || v != std::floor(v))
            fail(n, what + ": value '" + n.Scalar() + "' is not valid: expected a whole number " + std::to_string(min) +
                        ".." + std::to_string(max));
        return static_cast<int64_t>(v);
    }
    std::string text(const YAML::Node &n, const std::string &what) const {
        if (!n.IsScalar()) fail(n, what + ": expected a text, not " + (n.IsMap() ? "a map" : n.IsSequence() ? "a list" : "nothing"));
        return n.Scalar();
    }
    static std::string key(const YAML::Node &k) { return k.IsScalar() ? k.Scalar() : "(a non-scalar key)"; }
    std::vector<double> numbers(const YAML::Node &n, const std::string &what) const {
        if (!n.IsSequence()) fail(n, what + ": expected a list of numbers, e.g. [2.8, 4, 8]");
        std::vector<double> out;
        for (const auto &e : n) out.push_back(number(e, what));
        return out;
    }
};

// The settings table of the plugin a rig block names; empty when the block or the plugin
// is missing (the rig's own validation says so, with its position).
std::vector<binocle_param_desc> settingsOf(const YAML::Node &block, int32_t kind, const PluginHost &host) {
    if (!block.IsMap() || !block["plugin"] || !block["plugin"].IsScalar()) return {};
    const YAML::Node isolation = block["isolation"];
    const bool isolated = isolation && isolation.IsScalar() && isolation.Scalar() == "process";
    const PluginRecord *p = isolated ? host.describe(block["plugin"].Scalar(), kind) : host.lookup(block["plugin"].Scalar(), kind);
    return p ? p->params() : std::vector<binocle_param_desc>{};
}

const binocle_param_desc *setting(const std::vector<binocle_param_desc> &table, const std::string &name) {
    for (const auto &d : table)
        if (d.name && name == d.name) return &d;
    return nullptr;
}

// The rig paths a variable goes to, when the experiment does not say: every block of the
// rig whose plugin has a setting of that name (the source re-posed per test, a transform
// that takes camera_height_mm / inclination_deg). Found in the plugins' settings tables,
// so an experiment on any source or transform works without knowing them by name.
std::map<std::string, std::vector<std::string>> defaultBind(const YAML::Node &rig, const PluginHost &host) {
    std::map<std::string, std::vector<std::string>> b;
    const auto source = settingsOf(rig["source"], BINOCLE_KIND_STEREO_SOURCE, host);
    for (const auto &v : kVariables) {
        b[v];
        if (setting(source, v)) b[v].push_back("source." + v);
    }
    if (YAML::Node t = rig["transforms"]; t && t.IsSequence())
        for (size_t i = 0; i < t.size(); ++i) {
            const auto table = settingsOf(t[i], BINOCLE_KIND_CLOUD_TRANSFORM, host);
            for (const auto &v : kVariables)
                if (setting(table, v)) b[v].push_back("transforms." + std::to_string(i) + "." + v);
        }
    return b;
}

// A number the rig's source states for `key`, else the default of its plugin's setting of
// that name (e.g. a simulated head's pixel pitch); 0 when neither says.
double sourceFigure(const YAML::Node &rig, const std::string &key, const PluginHost &host) {
    const YAML::Node source = rig["source"];
    double v = 0;
    if (source.IsMap() && source[key] && YAML::convert<double>::decode(source[key], v)) return v;
    const auto *d = setting(settingsOf(source, BINOCLE_KIND_STEREO_SOURCE, host), key);
    if (d && d->default_value) {
        try {
            if (YAML::convert<double>::decode(YAML::Load(d->default_value), v)) return v;
        } catch (const YAML::Exception &) {
        }
    }
    return 0;
}

// A variable the tests set that goes nowhere in the rig is recorded in the results but
// changes nothing in the run: say so once, before anything runs.
void warnUnbound(const Experiment &e) {
    for (const auto &v : kVariables) {
        const auto it = e.bind.find(v);
        if (it != e.bind.end() && !it->second.empty()) continue;
        TestGeometry first = e.tests.front().geometry;
        const bool varies = std::any_of(e.tests.begin(), e.tests.end(), [&](const ExperimentTest &t) {
            TestGeometry g = t.geometry;
            return *field(g, v) != *field(first, v);
        });
        if (varies)
            spdlog::warn("experiment {}: the tests set different {} but no plugin of the rig has such a setting (and `bind:` "
                         "names none): it is recorded in the results, not applied",
                         e.name, v);
    }
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

// The node at a dotted rig path ("source.range_mm", "transforms.0.inclination_deg"), or
// an undefined node.
YAML::Node nodeAt(const YAML::Node &root, const std::string &path) {
    YAML::Node n = YAML::Clone(root);
    std::stringstream ss(path);
    for (std::string part; std::getline(ss, part, '.');) {
        if (!n.IsDefined() || n.IsNull() || n.IsScalar()) return YAML::Node(YAML::NodeType::Undefined);
        if (n.IsSequence()) {
            if (part.empty() || part.find_first_not_of("0123456789") != std::string::npos) return YAML::Node(YAML::NodeType::Undefined);
            n = n[std::stoul(part)];
        } else {
            n = n[part];
        }
    }
    return n;
}

// Uniform in [-1, 1) from a seed and a stream number, the same on every platform
// (std::uniform_real_distribution is not specified bit for bit).
double jitterUnit(uint32_t seed, uint32_t stream) {
    std::seed_seq seq{seed, stream, 0x6a177e2u};
    std::mt19937 gen(seq);
    return static_cast<double>(gen()) / 2147483648.0 - 1.0;
}

const Lens *lensFor(const Experiment &e, double focal_length_mm) {
    for (const auto &l : e.lens_table)
        if (std::fabs(l.focal_length_mm - focal_length_mm) < 1e-6) return &l;
    return nullptr;
}

} // namespace

uint32_t Experiment::seedOf(int repeat) const {
    if (!seeds.empty()) return seeds.at(static_cast<size_t>(repeat));
    return seed + static_cast<uint32_t>(repeat);
}

YAML::Node rigForTest(const Experiment &e, const ExperimentTest &t, int repeat) {
    YAML::Node rig = YAML::Clone(e.rig);
    if (const Lens *lens = lensFor(e, t.geometry.focal_length_mm))
        for (const auto &[path, value] : lens->set)
            applyOverride(rig, Override{path, value, "lens table " + e.lens_table_file + ": f = " + num(lens->focal_length_mm) + ": " + path});
    TestGeometry g = t.geometry;
    for (const auto &[var, paths] : e.bind) {
        const double *v = field(g, var);
        if (!v) continue;
        for (const auto &p : paths) applyOverride(rig, Override{p, num(*v), "test " + t.id + ": " + p + "=" + num(*v)});
    }
    for (const auto &[path, value] : t.set) applyOverride(rig, Override{path, value, "test " + t.id + ": set " + path});
    const bool repeating = e.repeatsOf(t) > 1 || !e.seeds.empty();
    if (repeat >= 0 && repeating) {
        const uint32_t seed = e.seedOf(repeat);
        applyOverride(rig, Override{e.seed_path, std::to_string(seed), "repeat " + std::to_string(repeat) + ": " + e.seed_path});
        for (size_t k = 0; k < e.jitter.size(); ++k) {
            const auto &[path, halfWidth] = e.jitter[k];
            const YAML::Node n = nodeAt(rig, path);
            double nominal = 0;
            if (!n.IsDefined() || !n.IsScalar() || !YAML::convert<double>::decode(n, nominal))
                throw Error(e.file + ": jitter: " + path + ": the rig of test " + t.id + " has no number there");
            const double v = nominal + halfWidth * jitterUnit(seed, static_cast<uint32_t>(k));
            applyOverride(rig, Override{path, num(v), "repeat " + std::to_string(repeat) + ": jitter " + path});
        }
    }
    return rig;
}

Experiment loadExperiment(const std::string &file, const PluginHost &host, const std::vector<std::string> &overrides) {
    std::error_code ec;
    Experiment e;
    e.file = fs::absolute(file, ec).lexically_normal().string();
    e.overrides = overrides;
    if (!fs::exists(e.file)) throw Error("experiment file " + file + " does not exist");
    Reader r{e.file};
    YAML::Node root;
    try {
        root = input::loadYamlFile(e.file);
    } catch (const input::YamlError &x) {
        throw Error(x.what());
    }
    if (!root.IsMap()) throw Error(e.file + ": expected a map with rig:, tests: ...");
    for (const auto &text : overrides) {
        const Override o = Override::parse(text);
        const std::string top = o.path.substr(0, o.path.find('.'));
        if (std::find(kTopKeys.begin(), kTopKeys.end(), top) == kTopKeys.end()) {
            const std::string hint = input::nearestWord(top, kTopKeys);
            throw Error("--set " + text + ": the experiment has no key '" + top + "'" +
                        (hint.empty() ? "" : "; did you mean '" + hint + "'?") + " (valid keys: " + join(kTopKeys) + ")");
        }
        applyOverride(root, o);
    }
    r.checkKeys(root, kTopKeys, "experiment");
    e.name = root["name"] ? r.text(root["name"], "name") : fs::path(e.file).stem().string();
    e.description = root["description"] ? r.text(root["description"], "description") : "";
    if (!root["rig"] || !root["rig"].IsScalar()) throw Error(e.file + ": missing key 'rig' (the base rig file)");
    fs::path rigPath = root["rig"].Scalar();
    if (rigPath.is_relative()) rigPath = fs::path(e.file).parent_path() / rigPath;
    e.rig_file = rigPath.lexically_normal().string();
    if (!fs::exists(e.rig_file)) r.fail(root["rig"], "rig: file '" + e.rig_file + "' does not exist");
    try {
        e.rig = input::loadYamlFile(e.rig_file);
    } catch (const input::YamlError &x) {
        throw Error(x.what());
    }
    if (!e.rig.IsMap()) throw Error(e.rig_file + ": expected a YAML map with source, matcher, ... at the top level");
    // rig_set: a partial rig laid over the base rig for every test (variants of a whole
    // experiment: `--set rig_set.source.image_width=640`).
    if (YAML::Node rs = root["rig_set"]) {
        if (!rs.IsMap()) r.fail(rs, "rig_set: expected a map, a partial rig laid over the base rig");
        std::function<void(const YAML::Node &, const std::string &)> lay = [&](const YAML::Node &n, const std::string &path) {
            if (n.IsMap()) {
                for (const auto &kv : n) lay(kv.second, path + (path.empty() ? "" : ".") + kv.first.as<std::string>());
                return;
            }
            applyOverride(e.rig, Override{path, yamlText(n), "rig_set: " + path});
        };
        lay(rs, "");
    }
    if (root["frames"]) e.frames = r.integer(root["frames"], "frames", 1, 1000000);
    if (root["lenses_mm"]) e.lenses_mm = r.numbers(root["lenses_mm"], "lenses_mm");
    if (root["baseline_range_mm"]) {
        auto b = r.numbers(root["baseline_range_mm"], "baseline_range_mm");
        if (b.size() != 2 || !(b[0] > 0) || b[1] < b[0]) r.fail(root["baseline_range_mm"], "baseline_range_mm: expected [min, max] in mm");
        e.baseline_min_mm = b[0];
        e.baseline_max_mm = b[1];
    }
    // The sensor figures: the experiment's, else what the source states or its plugin's
    // defaults (a simulated head); a source that states none gets no sensor-aware columns.
    e.pixel_pitch_um = root["pixel_pitch_um"] ? r.number(root["pixel_pitch_um"], "pixel_pitch_um")
                                              : sourceFigure(e.rig, "pixel_pitch_um", host);
    constexpr int64_t kMaxWidth = 32768;
    if (root["image_width_px"]) {
        e.image_width_px = static_cast<int>(r.integer(root["image_width_px"], "image_width_px", 1, kMaxWidth));
    } else {
        const double w = sourceFigure(e.rig, "image_width", host);
        e.image_width_px = std::isfinite(w) && w >= 1 && w <= kMaxWidth ? static_cast<int>(w) : 0;
    }

    if (root["image_height_px"]) e.image_height_px = static_cast<int>(r.integer(root["image_height_px"], "image_height_px", 1, kMaxWidth));
    else if (e.rig["source"] && e.rig["source"]["image_height"]) e.image_height_px = e.rig["source"]["image_height"].as<int>();
    if (YAML::Node d = root["disparity_search_px"]) {
        auto v = r.numbers(d, "disparity_search_px");
        if (v.size() != 2 || !(v[1] >= 1)) r.fail(d, "disparity_search_px: expected [min_disparity, num_disparities] of the matcher, e.g. [0, 64]");
        e.min_disparity_px = static_cast<int>(v[0]);
        e.num_disparities = static_cast<int>(v[1]);
    }
    if (YAML::Node p = root["panel"]) {
        if (!p.IsMap()) r.fail(p, "panel: expected {width_mm, height_mm, center_x_mm, base_z_mm}");
        r.checkKeys(p, {"width_mm", "height_mm", "center_x_mm", "base_z_mm"}, "panel");
        if (p["width_mm"]) e.panel.width_mm = r.number(p["width_mm"], "panel.width_mm");
        if (p["height_mm"]) e.panel.height_mm = r.number(p["height_mm"], "panel.height_mm");
        if (p["center_x_mm"]) e.panel.center_x_mm = r.number(p["center_x_mm"], "panel.center_x_mm");
        if (p["base_z_mm"]) e.panel.base_z_mm = r.number(p["base_z_mm"], "panel.base_z_mm");
        if (!(e.panel.width_mm > 0) || !(e.panel.height_mm > 0)) r.fail(p, "panel: width_mm and height_mm must be > 0");
    }

    // Repeats, seeds, jitter.
    auto wholeNumber = [&](const YAML::Node &n, const std::string &what, double lo, double hi) {
        const double v = r.number(n, what);
        if (v < lo || v > hi || v != std::floor(v))
            r.fail(n, what + " = " + num(v) + ": expected a whole number " + num(lo) + " .. " + num(hi));
        return v;
    };
    if (root["repeats"]) e.repeats = static_cast<int>(wholeNumber(root["repeats"], "repeats", 1, 10000));
    if (root["seed"]) e.seed = static_cast<uint32_t>(wholeNumber(root["seed"], "seed", 0, 4294967295.0));
    if (YAML::Node sl = root["seeds"]) {
        if (!sl.IsSequence()) r.fail(sl, "seeds: expected a list of whole numbers, one per repeat");
        for (const auto &x : sl) e.seeds.push_back(static_cast<uint32_t>(wholeNumber(x, "seeds", 0, 4294967295.0)));
    }
    if (root["seed_path"]) e.seed_path = root["seed_path"].as<std::string>();
    if (YAML::Node j = root["jitter"]) {
        if (!j.IsMap()) r.fail(j, "jitter: expected a map rig path -> half width (e.g. source.range_mm: 50)");
        for (const auto &kv : j) {
            const std::string path = kv.first.as<std::string>();
            const double w = r.number(kv.second, "jitter." + path);
            if (w < 0) r.fail(kv.second, "jitter." + path + " = " + num(w) + ": expected a half width >= 0");
            e.jitter.emplace_back(path, w);
        }
    }

    // Calibration per configuration.
    if (YAML::Node c = root["calibration"]) {
        e.calibration = c.as<std::string>();
        if (e.calibration != "exact" && e.calibration != "board")
            r.fail(c, "calibration: '" + e.calibration + "': expected exact (the source's own) or board (calibrated per test)");
    }
    if (YAML::Node b = root["board_calibration"]) {
        if (!b.IsMap()) r.fail(b, "board_calibration: expected {pairs, board, square_mm, capture}");
        r.checkKeys(b, {"pairs", "board", "square_mm", "capture", "max_frames"}, "board_calibration");
        auto &spec = e.board_calibration;
        if (b["pairs"]) spec.pairs = static_cast<int>(wholeNumber(b["pairs"], "board_calibration.pairs", 4, 1000));
        if (b["max_frames"]) spec.max_frames = static_cast<int>(wholeNumber(b["max_frames"], "board_calibration.max_frames", 1, 100000));
        const std::string board = b["board"] ? b["board"].as<std::string>() : "9x6";
        const double square = b["square_mm"] ? r.number(b["square_mm"], "board_calibration.square_mm") : 25.0;
        try {
            spec.board = BoardSpec::parse(board, square);
        } catch (const Error &x) {
            r.fail(b, std::string("board_calibration: ") + x.what());
        }
        if (YAML::Node cap = b["capture"]) {
            if (!cap.IsMap()) r.fail(cap, "board_calibration.capture: expected a map of rig paths to values");
            for (const auto &kv : cap) spec.capture.emplace_back(kv.first.as<std::string>(), yamlText(kv.second));
        }
    }
    if (e.calibration == "board" && e.board_calibration.capture.empty())
        r.fail(root["calibration"], "calibration: board needs board_calibration.capture: the rig settings that make the "
                                    "source show a chessboard (see configs/experiments/e1.yaml)");

    // The lens table: focal length -> rig overrides of that lens.
    if (YAML::Node lt = root["lens_table"]) {
        fs::path lp = lt.as<std::string>();
        if (lp.is_relative()) lp = fs::path(e.file).parent_path() / lp;
        e.lens_table_file = lp.lexically_normal().string();
        if (!fs::exists(e.lens_table_file)) r.fail(lt, "lens_table: file '" + e.lens_table_file + "' does not exist");
        YAML::Node table;
        try {
            table = YAML::LoadFile(e.lens_table_file);
        } catch (const YAML::ParserException &x) {
            throw Error(e.lens_table_file + ":" + std::to_string(x.mark.line + 1) + ": YAML syntax error: " + x.msg);
        }
        Reader lr{e.lens_table_file};
        if (!table.IsMap() || !table["lenses"] || !table["lenses"].IsSequence())
            throw Error(e.lens_table_file + ": expected a map with lenses: [{focal_length_mm, set: {rig path: value}}]");
        lr.checkKeys(table, {"name", "description", "lenses"}, "lens table");
        for (const auto &ln : table["lenses"]) {
            lr.checkKeys(ln, {"focal_length_mm", "set", "note"}, "lenses");
            Lens l;
            if (!ln["focal_length_mm"]) lr.fail(ln, "lenses: missing key 'focal_length_mm'");
            l.focal_length_mm = lr.number(ln["focal_length_mm"], "lenses.focal_length_mm");
            if (!(l.focal_length_mm > 0)) lr.fail(ln["focal_length_mm"], "lenses.focal_length_mm: expected > 0");
            if (lensFor(e, l.focal_length_mm)) lr.fail(ln, "lenses: focal length " + num(l.focal_length_mm) + " mm listed twice");
            if (YAML::Node st = ln["set"]) {
                if (!st.IsMap()) lr.fail(st, "lenses.set: expected a map of rig paths to values");
                for (const auto &kv : st) l.set.emplace_back(kv.first.as<std::string>(), yamlText(kv.second));
            }
            e.lens_table.push_back(std::move(l));
        }
        if (!root["lenses_mm"])
            for (const auto &l : e.lens_table) e.lenses_mm.push_back(l.focal_length_mm);
    }

    e.bind = defaultBind(e.rig, host);
    if (YAML::Node b = root["bind"]) {
        if (!b.IsMap()) r.fail(b, "bind: expected a map variable -> list of rig paths");
        r.checkKeys(b, kVariables, "bind");
        for (const auto &kv : b) {
            const std::string var = Reader::key(kv.first);
            std::vector<std::string> paths;
            if (kv.second.IsScalar()) paths.push_back(kv.second.Scalar());
            else if (kv.second.IsSequence())
                for (const auto &p : kv.second) paths.push_back(r.text(p, "bind." + var));
            else r.fail(kv.second, "bind." + var + ": expected a rig path or a list of them");
            e.bind[var] = paths;
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
            int64_t index = 0;
            if (n.IsSequence() && !input::parseInteger(part, index, nullptr, 0, static_cast<int64_t>(n.size()) - 1)) {
                found = false;
                break;
            }
            n = n.IsSequence() ? n[static_cast<size_t>(index)] : n[part];
        }
        double v = 0;
        if (found && n.IsDefined() && n.IsScalar() && input::parseReal(n.Scalar(), v)) {
            *field(defaults, var) = v;
            haveDefault.insert(var);
        }
    }
    if (YAML::Node d = root["defaults"]) {
        if (!d.IsMap()) r.fail(d, "defaults: expected a map of variables");
        r.checkKeys(d, kVariables, "defaults");
        for (const auto &kv : d) {
            const std::string var = Reader::key(kv.first);
            *field(defaults, var) = r.number(kv.second, "defaults." + var);
            haveDefault.insert(var);
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
        t.id = tn["id"] ? r.text(tn["id"], "tests[" + std::to_string(i) + "].id") : std::to_string(i + 1);
        t.line = tn.Mark().line + 1;
        // The id names the folder test_<id>/ under --out: it must stay a file name.
        if (std::string why; !input::isSafeName(t.id, &why))
            r.fail(tn["id"], "tests[" + std::to_string(i) + "].id '" + input::printable(t.id) + "': " + why +
                                 " (it names the folder test_<id>/ under --out)");
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
            for (const auto &kv : s) t.set.emplace_back(r.text(kv.first, "test " + t.id + ": set"), yamlText(kv.second));
        }
        if (tn["repeats"]) t.repeats = static_cast<int>(wholeNumber(tn["repeats"], "test " + t.id + ": repeats", 1, 10000));
        if (YAML::Node pp = tn["paper"]) {
            if (!pp.IsMap()) r.fail(pp, "test " + t.id + ": paper: expected a map figure -> value the paper reported");
            for (const auto &kv : pp) t.paper.emplace_back(kv.first.as<std::string>(), r.number(kv.second, "test " + t.id + ": paper." + kv.first.as<std::string>()));
        }
        if (!e.seeds.empty() && static_cast<int>(e.seeds.size()) < e.repeatsOf(t))
            r.fail(root["seeds"], "seeds: " + std::to_string(e.seeds.size()) + " seeds for " + std::to_string(e.repeatsOf(t)) +
                                      " repeats of test " + t.id + ": give one seed per repeat");
        if (!e.lens_table.empty() && !lensFor(e, t.geometry.focal_length_mm))
            r.fail(tn, "test " + t.id + ": focal_length_mm = " + num(t.geometry.focal_length_mm) + ": not in the lens table " +
                           e.lens_table_file);
        checkGeometry(e, t, r, tn);
        // The whole rig of this test must be valid before anything runs.
        try {
            rigFromNode(rigForTest(e, t, 0), e.rig_file, host);
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
            s.type = cn["type"] ? r.text(cn["type"], "charts.type") : "bars";
            if (s.type != "bars" && s.type != "scatter") r.fail(cn["type"], "charts: type '" + s.type + "': expected bars or scatter");
            if (!cn["metric"]) r.fail(cn, "charts: missing key 'metric' (e.g. eta_3d_percent)");
            s.metric = r.text(cn["metric"], "charts.metric");
            if (cn["x"]) s.x = r.text(cn["x"], "charts.x");
            s.title = cn["title"] ? r.text(cn["title"], "charts.title") : "";
            s.file = cn["file"] ? r.text(cn["file"], "charts.file") : s.metric + (s.type == "scatter" ? "_vs_" + s.x : "");
            // The chart is written as <--out>/<file>.png|svg: a file name, not a path.
            if (std::string why; !input::isSafeName(s.file, &why))
                r.fail(cn["file"] ? cn["file"] : cn, "charts.file '" + input::printable(s.file) + "': " + why +
                                                         " (the chart's file name under --out, without extension)");
            if (cn["reference_lines"]) s.reference_lines = r.numbers(cn["reference_lines"], "charts.reference_lines");
            e.charts.push_back(s);
        }
    } else {
        e.charts = {{"bars", "eta_3d_percent", "", e.name + ": stereo efficiency η3D per test", "eta_3d_bars", {70}},
                    {"bars", "eta_2d_percent", "", e.name + ": planar efficiency η2D per test", "eta_2d_bars", {70}},
                    {"scatter", "eta_3d_percent", "form_factor", e.name + ": η3D against the form factor FF", "eta_3d_vs_ff", {}}};
    }
    warnUnbound(e);
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
        e.rig = input::loadYamlFile(e.rig_file);
    } catch (const input::YamlError &x) {
        throw Error(x.what());
    }
    e.bind = defaultBind(e.rig, host);
    for (size_t i = 0; i < tests.size(); ++i) {
        ExperimentTest t;
        t.id = std::to_string(i + 1);
        t.geometry = tests[i];
        rigFromNode(rigForTest(e, t), e.rig_file, host); // throws with the reason
        e.tests.push_back(t);
    }
    e.charts = {{"scatter", "eta_3d_percent", "form_factor", name + ": η3D against the form factor FF", "eta_3d_vs_ff", {}}};
    warnUnbound(e);
    return e;
}

namespace {

using OJson = nlohmann::ordered_json;

// Main columns first (the names of METHOD.md), then every other figure an evaluator
// reported, as "<evaluator>.<metric>".
const std::vector<std::string> kMainMetrics = {"epsilon_x_percent", "epsilon_y_percent", "epsilon_z_percent",
                                               "eta_2d_percent", "eta_3d_percent"};
// The figures summarised over repeats (mean, sd, 95 % CI).
const std::vector<std::string> kRepeatedMetrics = {"epsilon_x_percent", "epsilon_y_percent", "epsilon_z_percent",
                                                   "eta_2d_percent",    "eta_3d_percent",    "valid_pixel_ratio"};
// Row keys that are not numbers.
const std::vector<std::string> kRowTextKeys = {"test", "status", "error"};

struct Row {
    const ExperimentTest *test = nullptr;
    std::vector<std::pair<std::string, double>> values; // in column order
    std::string status = "ok", error;
    OJson details = OJson::object(); // repeats, calibration, paper: results.json only
    double get(const std::string &k) const {
        for (const auto &[n, v] : values)
            if (n == k) return v;
        return NAN;
    }
    void put(const std::string &k, double v) {
        for (auto &[n, x] : values)
            if (n == k) {
                x = v;
                return;
            }
        values.emplace_back(k, v);
    }
    OJson toJson() const {
        OJson row = OJson::object();
        row["test"] = test->id;
        row["status"] = status;
        for (const auto &[n, v] : values) row[n] = std::isfinite(v) ? OJson(v) : OJson();
        if (!error.empty()) row["error"] = error;
        for (const auto &[k, v] : details.items()) row[k] = v;
        return row;
    }
    // From a results.json row (merge): numbers and nulls are values, objects details.
    static Row fromJson(const OJson &j, const ExperimentTest *t) {
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
};

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
                  "(framework/method/predictors.hpp)";
    return out;
}

// What produced the results, for the report: binocle's and each plugin's version.
// Only the plugins the rig names: the same list whichever others the host has opened.
OJson software(const PluginHost &host, const YAML::Node &rig) {
    std::set<std::string> named;
    auto add = [&](const YAML::Node &block) {
        if (block.IsMap() && block["plugin"] && block["plugin"].IsScalar()) named.insert(block["plugin"].Scalar());
    };
    for (const char *key : {"source", "matcher"}) add(rig[key]);
    for (const char *key : {"transforms", "evaluators"})
        if (rig[key] && rig[key].IsSequence())
            for (const auto &b : rig[key]) add(b);
    OJson plugins = OJson::array();
    for (const auto &name : named) { // sorted by name
        const PluginRecord *p = host.find(name);
        for (const auto &d : host.described()) // an isolated plugin is described, not opened
            if (!p && d.name == name) p = &d;
        if (p) plugins.push_back({{"name", p->name}, {"version", p->version}, {"kind", kindName(p->kind)}});
    }
    return {{"binocle", BINOCLE_VERSION}, {"opencv", CV_VERSION}, {"plugins", std::move(plugins)}};
}

struct TablesMeta {
    std::vector<std::string> test_ids; // every test of the experiment, in file order
    int shard_index = 1, shard_count = 1;
    OJson software; // software(host)
};

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
    doc["description"] = e.description;
    doc["file"] = e.file;
    doc["rig"] = e.rig_file;
    doc["rig_yaml"] = yamlBlock(e.rig);
    doc["software"] = meta.software;
    doc["overrides"] = e.overrides;
    doc["calibration"] = e.calibration;
    doc["test_ids"] = meta.test_ids;
    if (meta.shard_count > 1) doc["shard"] = {{"index", meta.shard_index}, {"count", meta.shard_count}};
    doc["units"] = {{"length", "mm"}, {"angle", "deg"}, {"errors_and_efficiencies", "%"}};
    doc["statistics"] = "with repeats: each figure is the mean over repeats; <figure>_sd the sample standard deviation, "
                        "<figure>_ci95_low/_high the 95 % confidence interval of the mean (Student t, n - 1 degrees of "
                        "freedom); per-repeat values under per_repeat";
    doc["predictors"] = predictorRho(rows);
    doc["tests"] = std::move(tests);
    writeFileAtomic((fs::path(dir) / "results.json").string(), doc.dump(2) + "\n");
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

// The columns every row starts with: the test's variables and the design figures.
void putDesign(Row &row, const Experiment &e, const ExperimentTest &t) {
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
        d.image_height_px = e.image_height_px;
        d.min_disparity_px = e.min_disparity_px;
        d.num_disparities = e.num_disparities;
        d.camera_height_mm = g.camera_height_mm;
        d.inclination_deg = g.inclination_deg;
        const method::DesignFigures f = method::designFigures(d, g.range_mm, 0.25, &e.panel);
        row.put("expected_disparity_px", f.disparity_px);
        row.put("depth_resolution_mm", f.depth_resolution_mm);
        row.put("stereo_field_width_mm", f.stereo_field_width_mm);
        const method::PredictorValues p = method::predictors(d, g.range_mm, e.panel);
        row.put("predictor.ff_band", p.ff_band);
        row.put("predictor.depth_resolution", p.depth_resolution);
        row.put("predictor.sensor_aware", p.sensor_aware);
    } else {
        row.put("predictor.ff_band", -method::formFactorBandDistance(method::formFactor(g.baseline_mm, g.focal_length_mm, g.range_mm)));
    }
}

// One repeat of a test: the pipeline over the experiment's frames; figures averaged over
// the frames ("<evaluator>.<metric>" and the bare main metrics) and the valid-pixel ratio.
std::vector<std::pair<std::string, double>> runRepeat(const Experiment &e, const YAML::Node &rigNode, const PluginHost &host,
                                                      const std::string &outDir) {
    RigConfig rig = rigFromNode(rigNode, e.rig_file, host);
    Pipeline pipeline(rig, host);
    RunOptions run;
    run.max_frames = e.frames;
    run.out_dir = outDir;
    run.progress = false;
    std::vector<std::pair<std::string, double>> sums;
    std::vector<int> counts;
    double valid = 0;
    int frames = 0;
    pipeline.run(run, [&](const FrameResult &fr) {
        ++frames;
        valid += fr.valid_pixel_ratio;
        for (const auto &figure : fr.figures) {
            const std::string &name = figure.first; // a structured binding cannot be captured in C++17 (clang)
            const double value = figure.second;
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
    std::vector<std::pair<std::string, double>> out;
    auto put = [&](const std::string &k, double v) {
        for (auto &[n, x] : out)
            if (n == k) return;
        out.emplace_back(k, v);
    };
    for (const auto &k : kMainMetrics) put(k, NAN);
    out.emplace_back("valid_pixel_ratio", frames ? valid / frames : NAN);
    for (size_t k = 0; k < sums.size(); ++k) {
        const double mean = counts[k] ? sums[k].second / counts[k] : NAN;
        const std::string &name = sums[k].first; // "<evaluator>.<metric>"
        const std::string metric = name.substr(name.find('.') + 1);
        if (std::find(kMainMetrics.begin(), kMainMetrics.end(), metric) != kMainMetrics.end())
            for (auto &[n, x] : out)
                if (n == metric && !std::isfinite(x)) x = mean;
        out.emplace_back(name, mean);
    }
    return out;
}

Row runTest(const Experiment &e, const ExperimentTest &t, const PluginHost &host, const std::string &outDir) {
    Row row;
    row.test = &t;
    putDesign(row, e, t);
    for (const auto &k : kMainMetrics) row.put(k, NAN);
    row.put("valid_pixel_ratio", NAN);
    const int repeats = e.repeatsOf(t);
    const bool repeating = repeats > 1 || !e.seeds.empty();
    if (repeating)
        for (const auto &k : kRepeatedMetrics)
            for (const char *suffix : {"_sd", "_ci95_low", "_ci95_high"}) row.put(k + suffix, NAN);
    row.put("repeats", repeats);
    const std::string testDir = (fs::path(outDir) / ("test_" + t.id)).string();
    try {
        std::string calibrationFile;
        if (e.calibration == "board") {
            const std::string name = "calibration/calib_B" + num(std::round(t.geometry.baseline_mm)) + "_f" +
                                     num(std::round(t.geometry.focal_length_mm * 10) / 10) + ".yml";
            calibrationFile = (fs::path(testDir) / name).string();
            const double pitch = e.pixel_pitch_um;
            BoardCalibrationOutcome c =
                calibrateConfiguration(rigForTest(e, t), e.rig_file, e.board_calibration, host, calibrationFile, pitch);
            row.put("calibration_rms_px", c.rms_px);
            row.put("calibration_baseline_error_percent", c.baseline_error_percent);
            row.put("calibration_focal_length_error_percent", c.focal_length_error_percent);
            row.put("calibration_pairs_used", c.pairs_used);
            c.file = "test_" + t.id + "/" + name; // relative: identical whichever folder the run wrote to
            row.details["calibration"] = c.toJson();
        }
        // Per repeat: every figure; the outputs (disparity, cloud, views) of the first only.
        std::vector<std::vector<std::pair<std::string, double>>> results;
        OJson perRepeat = OJson::array();
        for (int k = 0; k < repeats; ++k) {
            YAML::Node rig = rigForTest(e, t, k);
            if (!calibrationFile.empty()) rig["calibration"] = calibrationFile;
            std::string repeatDir = testDir;
            if (k > 0) { // later repeats: their summary and evaluator views, no images or clouds
                repeatDir = (fs::path(testDir) / ("repeat_" + std::to_string(k))).string();
                for (const char *o : {"disparity_png", "disparity_color", "disparity_pfm", "cloud_ply", "rectified_png"})
                    rig["outputs"][o] = false;
            }
            results.push_back(runRepeat(e, rig, host, repeatDir));
            if (repeating) {
                OJson one = OJson::object();
                one["seed"] = e.seedOf(k);
                if (!e.jitter.empty()) {
                    OJson j = OJson::object();
                    for (const auto &[path, w] : e.jitter) {
                        const YAML::Node n = nodeAt(rig, path);
                        j[path] = n.IsScalar() ? OJson(n.as<double>()) : OJson();
                    }
                    one["jitter"] = j;
                }
                for (const auto &[n, v] : results.back())
                    if (std::find(kRepeatedMetrics.begin(), kRepeatedMetrics.end(), n) != kRepeatedMetrics.end())
                        one[n] = std::isfinite(v) ? OJson(v) : OJson();
                perRepeat.push_back(one);
            }
        }
        // Means over the repeats, in the order the first repeat reported them.
        for (const auto &[name, unused] : results.front()) {
            (void)unused;
            std::vector<double> samples;
            for (const auto &r : results)
                for (const auto &[n, v] : r)
                    if (n == name) samples.push_back(v);
            const method::Summary s = method::summarize(samples);
            row.put(name, s.n ? s.mean : NAN);
            if (repeating && std::find(kRepeatedMetrics.begin(), kRepeatedMetrics.end(), name) != kRepeatedMetrics.end()) {
                row.put(name + "_sd", s.n ? s.sd : NAN);
                row.put(name + "_ci95_low", s.ci95_low);
                row.put(name + "_ci95_high", s.ci95_high);
            }
        }
        if (repeating) row.details["per_repeat"] = perRepeat;
    } catch (const std::exception &x) {
        row.status = "failed";
        row.error = x.what();
        spdlog::error("experiment: {} failed: {}", testLabel(t), x.what());
    }
    if (!t.paper.empty()) {
        OJson paper = OJson::object();
        for (const auto &[k, reported] : t.paper) {
            const double measured = row.get(k);
            row.put("paper_reported." + k, reported); // not "paper.": the paper evaluator's figures are named so
            paper[k] = {{"reported", reported},
                        {"measured", std::isfinite(measured) ? OJson(measured) : OJson()},
                        {"difference", std::isfinite(measured) ? OJson(measured - reported) : OJson()}};
        }
        row.details["paper_reported"] = paper;
    }
    return row;
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

std::pair<int, int> parseShard(const std::string &text) {
    const auto slash = text.find('/');
    int k = 0, n = 0;
    try {
        size_t a = 0, b = 0;
        if (slash == std::string::npos) throw std::invalid_argument(text);
        k = std::stoi(text.substr(0, slash), &a);
        n = std::stoi(text.substr(slash + 1), &b);
        if (a != slash || b != text.size() - slash - 1) throw std::invalid_argument(text);
    } catch (const std::logic_error &) {
        throw Error("--shard " + text + ": expected K/N, e.g. --shard 2/8 (the second of eight shares)");
    }
    if (n < 1 || k < 1 || k > n) throw Error("--shard " + text + ": expected 1 <= K <= N");
    return {k, n};
}

ExperimentResult runExperiment(const Experiment &e, const PluginHost &host, const ExperimentOptions &options) {
    if (options.out_dir.empty()) throw Error("experiment: an output folder is needed (--out DIR)");
    if (options.shard_count < 1 || options.shard_index < 1 || options.shard_index > options.shard_count)
        throw Error("experiment: shard " + std::to_string(options.shard_index) + "/" + std::to_string(options.shard_count) +
                    ": expected 1 <= K <= N");
    std::error_code ec;
    fs::create_directories(options.out_dir, ec);
    if (ec) throw Error("--out " + options.out_dir + ": cannot create the folder: " + ec.message());
    std::vector<const ExperimentTest *> selected;
    for (size_t p = 0; p < e.tests.size(); ++p) {
        const auto &t = e.tests[p];
        if (static_cast<int>(p % static_cast<size_t>(options.shard_count)) != options.shard_index - 1) continue;
        if (options.only.empty() || std::find(options.only.begin(), options.only.end(), t.id) != options.only.end())
            selected.push_back(&t);
    }
    if (selected.empty() && (options.shard_count == 1 || !options.only.empty()))
        throw Error("experiment " + e.file + ": no test selected (ids: " + join(options.only) + ")");
    // A partial run (--tests, or a shard) into a folder that already holds this or another
    // experiment's table would replace it with fewer rows: refused, nothing is touched.
    if (selected.size() < e.tests.size()) {
        const fs::path existing = fs::path(options.out_dir) / "results.json";
        if (fs::exists(existing, ec))
            throw Error("--out " + options.out_dir + " already holds results (" + existing.string() +
                        "); a partial run (--tests or --shard) would replace that table with " +
                        std::to_string(selected.size()) + " of " + std::to_string(e.tests.size()) +
                        " tests: run into a new folder and join them with `binocle experiment merge OUT DIR...`, "
                        "or run every test");
    }
    const TablesMeta meta = metaOf(e, options.shard_index, options.shard_count, host);

    std::vector<Row> rows;
    Progress progress(options.progress, "test", static_cast<int64_t>(selected.size()));
    const auto start = std::chrono::steady_clock::now();
    for (size_t i = 0; i < selected.size(); ++i) {
        const ExperimentTest &t = *selected[i];
        progress.update(static_cast<int64_t>(i), testLabel(t));
        const auto t0 = std::chrono::steady_clock::now();
        Row row = runTest(e, t, host, options.out_dir);
        row.put("seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        rows.push_back(std::move(row));
        // Rewritten after every test: an interrupted experiment keeps what it measured.
        writeTables(options.out_dir, e, rows, meta);
    }
    if (rows.empty()) writeTables(options.out_dir, e, rows, meta); // an empty shard still says so
    progress.update(static_cast<int64_t>(selected.size()), "done");
    progress.finish();
    writeCharts(options.out_dir, e, rows);
    ExperimentResult result = resultOf(rows);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

ExperimentResult mergeExperimentResults(const std::string &out_dir, const std::vector<std::string> &dirs, const PluginHost &host) {
    if (dirs.empty()) throw Error("experiment merge: no folder to merge (binocle experiment merge OUT DIR...)");
    std::vector<OJson> docs;
    for (const auto &d : dirs) {
        const std::string path = (fs::path(d) / "results.json").string();
        std::ifstream in(path);
        if (!in) throw Error("experiment merge: " + path + " cannot be read (is " + d + " an experiment's output folder?)");
        try {
            docs.push_back(OJson::parse(in));
        } catch (const nlohmann::json::exception &x) {
            throw Error("experiment merge: " + path + ": not valid JSON: " + x.what());
        }
        if (!docs.back().contains("file") || !docs.back().contains("tests"))
            throw Error("experiment merge: " + path + ": no 'file' or 'tests': not an experiment's results.json");
    }
    const std::string file = docs[0]["file"].get<std::string>();
    const auto overrides = docs[0].value("overrides", std::vector<std::string>{});
    for (size_t i = 1; i < docs.size(); ++i) {
        if (docs[i]["file"].get<std::string>() != file)
            throw Error("experiment merge: " + dirs[i] + " holds results of " + docs[i]["file"].get<std::string>() + ", " + dirs[0] +
                        " of " + file + ": not the same experiment");
        if (docs[i].value("overrides", std::vector<std::string>{}) != overrides)
            throw Error("experiment merge: " + dirs[i] + " ran with other --set overrides than " + dirs[0]);
    }
    const Experiment e = loadExperiment(file, host, overrides);
    std::map<std::string, std::pair<OJson, size_t>> byId; // test id -> (row, folder index)
    std::set<int> shards;
    int shardCount = 0;
    for (size_t i = 0; i < docs.size(); ++i) {
        if (docs[i].contains("shard")) {
            shards.insert(docs[i]["shard"]["index"].get<int>());
            shardCount = docs[i]["shard"]["count"].get<int>();
        }
        for (const auto &row : docs[i]["tests"]) {
            const std::string id = row["test"].get<std::string>();
            if (byId.count(id))
                throw Error("experiment merge: test " + id + " is in both " + dirs[byId[id].second] + " and " + dirs[i]);
            byId[id] = {row, i};
        }
    }
    std::vector<Row> rows;
    for (const auto &t : e.tests) {
        auto it = byId.find(t.id);
        if (it == byId.end()) continue;
        rows.push_back(Row::fromJson(it->second.first, &t));
        byId.erase(it);
    }
    if (!byId.empty()) throw Error("experiment merge: test " + byId.begin()->first + " is not in " + file);
    if (shardCount > 0 && static_cast<int>(shards.size()) == shardCount && rows.size() != e.tests.size())
        throw Error("experiment merge: all " + std::to_string(shardCount) + " shards given but only " + std::to_string(rows.size()) +
                    " of " + std::to_string(e.tests.size()) + " tests found");
    std::error_code ec;
    fs::create_directories(out_dir, ec);
    if (ec) throw Error("experiment merge: " + out_dir + ": cannot create the folder: " + ec.message());
    for (size_t i = 0; i < docs.size(); ++i)
        for (const auto &row : docs[i]["tests"]) {
            const fs::path from = fs::path(dirs[i]) / ("test_" + row["test"].get<std::string>());
            if (!fs::exists(from)) continue;
            const fs::path to = fs::path(out_dir) / from.filename();
            if (fs::equivalent(fs::path(dirs[i]), fs::path(out_dir), ec)) continue;
            fs::copy(from, to, fs::copy_options::recursive | fs::copy_options::overwrite_existing, ec);
            if (ec) throw Error("experiment merge: copying " + from.string() + " to " + to.string() + ": " + ec.message());
        }
    writeTables(out_dir, e, rows, metaOf(e, 1, 1, host));
    writeCharts(out_dir, e, rows);
    return resultOf(rows);
}

} // namespace binocle
