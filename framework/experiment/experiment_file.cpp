// SPDX-License-Identifier: MIT
// Experiment files: read and validate an experiment YAML (and its lens table) into an
// Experiment, every test's rig checked against the plugins before anything runs.
#include "experiment/experiment.hpp"
#include "experiment/test_rig.hpp"

#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "files/atomic_file.hpp"
#include "input/integer_range.hpp"
#include "input/names.hpp"
#include "input/yaml_file.hpp"

#include <binocle/numbers.hpp>
#include <binocle/text.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace binocle {

using namespace experiment;

namespace {

const std::vector<std::string> kTopKeys = {
    "name",    "description", "rig",        "frames",     "lenses_mm",         "baseline_range_mm", "pixel_pitch_um",
    "image_width_px", "image_height_px", "disparity_search_px", "bind", "defaults", "tests", "charts", "repeats",
    "seed",    "seeds",       "seed_path",  "jitter",     "calibration",       "board_calibration", "lens_table", "panel",
    "rig_set", "dataset",   "dataset_path", "scenes",   "scene_set", "matcher"};
const std::vector<std::string> kTestKeys = {"id", "baseline_mm", "focal_length_mm", "range_mm", "camera_height_mm",
                                            "inclination_deg", "set", "repeats", "paper"};

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
    // One strict reader of numbers (binocle/numbers.hpp): decimal, finite.
    double number(const YAML::Node &n, const std::string &what) const {
        double v = 0;
        std::string why;
        if (!n.IsScalar() || !sdk::parseDecimalReal(n.Scalar(), v, &why))
            fail(n, what + ": value '" + (n.IsScalar() ? sdk::printable(n.Scalar()) : std::string("(not a scalar)")) +
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

// Whole numbers given as reals (repeats, seeds): checked against [lo, hi] before the cast.
double wholeNumber(const Reader &r, const YAML::Node &n, const std::string &what, double lo, double hi) {
    const double v = r.number(n, what);
    if (v < lo || v > hi || v != std::floor(v)) r.fail(n, what + " = " + num(v) + ": expected a whole number " + num(lo) + " .. " + num(hi));
    return v;
}

// An experiment, its rig and its lens table are a few hundred nodes as written. YAML
// aliases can make a small file a huge tree (an alias of a list of aliases ...), which
// every later step would walk: the tree is counted as it will be walked, aliases
// expanded, and refused past this bound before anything else reads it.
constexpr size_t kMaxExpandedNodes = 100000;

void checkExpandedSize(const YAML::Node &root, const std::string &file) {
    size_t count = 0;
    std::vector<YAML::Node> stack{root};
    while (!stack.empty()) {
        const YAML::Node n = stack.back();
        stack.pop_back();
        if (++count > kMaxExpandedNodes)
            throw Error(file + ": more than " + std::to_string(kMaxExpandedNodes) +
                        " YAML nodes once its aliases are expanded (*name repeats what &name marks): expected a "
                        "file of at most a few thousand values");
        if (n.IsMap())
            for (const auto &kv : n) {
                stack.push_back(kv.first);
                stack.push_back(kv.second);
            }
        else if (n.IsSequence())
            for (const auto &x : n) stack.push_back(x);
    }
}

YAML::Node loadYaml(const std::string &file) {
    YAML::Node root;
    try {
        root = input::loadYamlFile(file);
    } catch (const input::YamlError &x) {
        throw Error(x.what());
    }
    checkExpandedSize(root, file);
    return root;
}

// The base rig is read (its plugins' settings, its figures) before each test's rig is
// validated in full: its shape is checked first, so that a file that is not a rig (a
// calibration, `source: sim`) is named with what was expected, not with yaml-cpp's words.
void checkRigShape(const YAML::Node &rig, const std::string &file, const std::string &namedAt) {
    const std::string expected = "expected a rig: a YAML map with source: {plugin: NAME, ...} and matcher: {plugin: NAME, ...}";
    if (!rig.IsMap()) throw Error(namedAt + ": " + file + " is not a rig (" + expected + ")");
    std::vector<std::string> keys;
    for (const auto &kv : rig) keys.push_back(kv.first.IsScalar() ? sdk::printable(kv.first.Scalar(), 40) : "(not a text)");
    for (const char *block : {"source", "matcher"}) {
        const YAML::Node b = rig[block];
        if (!b.IsDefined())
            throw Error(namedAt + ": " + file + " has no '" + block + "' block: " + expected + " (its top-level keys: " +
                        (keys.empty() ? "none" : join(keys)) + ")");
        const std::string at = b.Mark().is_null() ? file : file + ":" + std::to_string(b.Mark().line + 1) + ":" +
                                                               std::to_string(b.Mark().column + 1);
        if (!b.IsMap() || !b["plugin"].IsDefined() || !b["plugin"].IsScalar())
            throw Error(at + ": " + block + ": value " +
                        (b.IsScalar() ? "'" + sdk::printable(b.Scalar(), 40) + "'" : b.IsSequence() ? "(a list)" : "(empty)") +
                        " is not valid: expected a map with 'plugin: <name>' and the plugin's settings (e.g. " + block +
                        ": {plugin: " + (std::string(block) == "source" ? "sim" : "bm") + "})");
    }
}

// The experiment file's tree with the --set overrides applied (each naming a top key).
YAML::Node readRoot(const Experiment &e, const std::string &file, const std::vector<std::string> &overrides) {
    if (!fs::exists(e.file)) throw Error("experiment file " + file + " does not exist");
    YAML::Node root = loadYaml(e.file);
    if (!root.IsMap()) throw Error(e.file + ": expected a map with rig:, tests: ...");
    for (const auto &text : overrides) {
        const Override o = Override::parse(text);
        const std::string top = o.path.substr(0, o.path.find('.'));
        if (std::find(kTopKeys.begin(), kTopKeys.end(), top) == kTopKeys.end()) {
            const std::string hint = input::nearestWord(top, kTopKeys);
            throw OverrideError("--set " + text + ": the experiment has no key '" + top + "'" +
                        (hint.empty() ? "" : "; did you mean '" + hint + "'?") + " (valid keys: " + join(kTopKeys) + ")");
        }
        applyOverride(root, o);
    }
    if (!overrides.empty()) checkExpandedSize(root, e.file + " (with --set)");
    return root;
}

// `matcher:` replaces the rig's matcher block for every test (`--set matcher=bm`, or a map
// with the plugin's settings); it goes into rig_set, so that every test's rig gets it.
void layMatcher(Experiment &e, const YAML::Node &root, const Reader &r) {
    auto lay = [&](const YAML::Node &at, const std::string &path, const std::string &value) {
        try {
            applyOverride(e.rig, Override{path, value, path + "=" + value});
            e.rig_set.emplace_back(path, value);
        } catch (const OverrideError &x) {
            r.fail(at, std::string(x.what()) + " (laid over the base rig " + e.rig_file + ")");
        }
    };
    if (const YAML::Node m = root["matcher"]) {
        if (m.IsScalar()) lay(m, "matcher", "{plugin: " + m.Scalar() + "}");
        else if (m.IsMap() && m["plugin"]) lay(m, "matcher", yamlText(m));
        else r.fail(m, "matcher: expected a plugin name (matcher=bm) or a map {plugin: NAME, its settings}");
    }
}

// `dataset:` a folder of scene folders (relative: from the current folder, as a
// command-line path): a test per sub-folder, in natural order, named after it, that writes
// the scene's folder to the rig path `dataset_path` (default source.folder); `scenes:`
// picks some by name. A folder without sub-folders is one scene itself.
YAML::Node datasetTests(const YAML::Node &root, const Reader &r) {
    if (root["tests"]) r.fail(root["tests"], "tests: not with dataset: (its scene folders are the tests)");
    const YAML::Node d = root["dataset"];
    const std::string path = root["dataset_path"] ? r.text(root["dataset_path"], "dataset_path") : "source.folder";
    std::error_code ec;
    const fs::path folder = fs::absolute(r.text(d, "dataset"), ec).lexically_normal();
    if (!fs::is_directory(folder))
        r.fail(d, "dataset: folder '" + folder.string() + "' does not exist (a relative path is taken from the current folder)");
    std::vector<std::string> names;
    for (const auto &entry : fs::directory_iterator(folder, ec))
        if (entry.is_directory() && entry.path().filename().string()[0] != '.') names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    std::vector<fs::path> scenes;
    if (names.empty()) scenes.push_back(folder);
    if (const YAML::Node pick = root["scenes"]; pick && !(pick.IsSequence() && pick.size() == 0)) {
        if (!pick.IsSequence()) r.fail(pick, "scenes: expected a list of scene folder names, e.g. [teddy, cones]");
        for (const auto &n : pick) {
            const std::string name = r.text(n, "scenes");
            if (std::find(names.begin(), names.end(), name) == names.end())
                r.fail(n, "scenes: '" + sdk::printable(name) + "' is not a folder of " + folder.string() + " (its folders: " +
                              join(names) + ")");
            scenes.push_back(folder / name);
        }
    } else {
        for (const auto &n : names) scenes.push_back(folder / n);
    }
    // scene_set: {SCENE: {rig path: value}}: what one scene needs of its own (its search range).
    const YAML::Node own = root["scene_set"];
    if (own && !own.IsMap()) r.fail(own, "scene_set: expected a map scene -> {rig path: value}");
    YAML::Node tests(YAML::NodeType::Sequence);
    for (const fs::path &scene : scenes) {
        YAML::Node t;
        const std::string id = scene.filename().string();
        if (id == "mean") r.fail(d, "dataset: " + scene.string() + ": a scene may not be named 'mean' (the row of the means)");
        t["id"] = id;
        t["set"][path] = scene.string();
        if (own && own[id]) {
            if (!own[id].IsMap()) r.fail(own[id], "scene_set." + id + ": expected a map {rig path: value}");
            for (const auto &kv : own[id]) t["set"][r.text(kv.first, "scene_set." + id)] = kv.second;
        }
        tests.push_back(t);
    }
    return tests;
}

// The base rig, with `rig_set:` laid over it.
void readRig(Experiment &e, const YAML::Node &root, const Reader &r) {
    if (!root["rig"] || !root["rig"].IsScalar()) throw Error(e.file + ": missing key 'rig' (the base rig file)");
    fs::path rigPath = root["rig"].Scalar();
    if (rigPath.is_relative()) rigPath = fs::path(e.file).parent_path() / rigPath;
    e.rig_file = rigPath.lexically_normal().string();
    if (!fs::exists(e.rig_file)) r.fail(root["rig"], "rig: file '" + e.rig_file + "' does not exist");
    e.rig = loadYaml(e.rig_file);
    e.rig_text = readTextFile(e.rig_file);
    checkRigShape(e.rig, e.rig_file, r.where(root["rig"]) + ": rig");
    layMatcher(e, root, r);
    // rig_set: a partial rig laid over the base rig for every test (variants of a whole
    // experiment: `--set rig_set.source.image_width=640`).
    if (YAML::Node rs = root["rig_set"]) {
        if (!rs.IsMap()) r.fail(rs, "rig_set: expected a map, a partial rig laid over the base rig");
        std::function<void(const YAML::Node &, const std::string &)> lay = [&](const YAML::Node &n, const std::string &path) {
            if (n.IsMap()) {
                for (const auto &kv : n) lay(kv.second, path + (path.empty() ? "" : ".") + r.text(kv.first, "rig_set (a rig path)"));
                return;
            }
            try {
                applyOverride(e.rig, Override{path, yamlText(n), "rig_set: " + path});
                e.rig_set.emplace_back(path, yamlText(n));
            } catch (const OverrideError &x) { // a mistake of the file (or of its --set rig_set...), named there
                r.fail(n, std::string(x.what()) + " (laid over the base rig " + e.rig_file + ")");
            }
        };
        lay(rs, "");
    }
}

// Frames, lenses, baselines, the sensor figures, the matcher's search and the panel.
void readHead(Experiment &e, const YAML::Node &root, const Reader &r, const PluginHost &host) {
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
    e.head.pixel_pitch_um = root["pixel_pitch_um"] ? r.number(root["pixel_pitch_um"], "pixel_pitch_um")
                                              : sourceFigure(e.rig, "pixel_pitch_um", host);
    constexpr int64_t kMaxWidth = 32768;
    if (root["image_width_px"]) {
        e.head.image_width_px = static_cast<int>(r.integer(root["image_width_px"], "image_width_px", 1, kMaxWidth));
    } else {
        const double w = sourceFigure(e.rig, "image_width", host);
        e.head.image_width_px = std::isfinite(w) && w >= 1 && w <= kMaxWidth ? static_cast<int>(w) : 0;
    }

    if (root["image_height_px"]) e.head.image_height_px = static_cast<int>(r.integer(root["image_height_px"], "image_height_px", 1, kMaxWidth));
    else if (const YAML::Node s = e.rig["source"]; s.IsMap() && s["image_height"]) // as the rig states it, else unknown
        e.head.image_height_px = static_cast<int>(Reader{e.rig_file}.integer(s["image_height"], "source.image_height", 1, kMaxWidth));
    if (YAML::Node d = root["disparity_search_px"]) {
        auto v = r.numbers(d, "disparity_search_px");
        if (v.size() != 2 || !(v[1] >= 1)) r.fail(d, "disparity_search_px: expected [min_disparity, num_disparities] of the matcher, e.g. [0, 64]");
        e.head.min_disparity_px = static_cast<int>(v[0]);
        e.head.num_disparities = static_cast<int>(v[1]);
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
}

// Repeats, seeds, jitter.
void readRepeats(Experiment &e, const YAML::Node &root, const Reader &r) {
    if (root["repeats"]) e.repeats = static_cast<int>(wholeNumber(r, root["repeats"], "repeats", 1, 10000));
    if (root["seed"]) e.seed = static_cast<uint32_t>(wholeNumber(r, root["seed"], "seed", 0, 4294967295.0));
    if (YAML::Node sl = root["seeds"]) {
        if (!sl.IsSequence()) r.fail(sl, "seeds: expected a list of whole numbers, one per repeat");
        for (const auto &x : sl) {
            const auto seed = static_cast<uint32_t>(wholeNumber(r, x, "seeds", 0, 4294967295.0));
            // Two repeats with one seed render the same images: their spread would read as
            // a precision the experiment never measured (sd 0).
            if (std::find(e.seeds.begin(), e.seeds.end(), seed) != e.seeds.end())
                r.fail(x, "seeds: " + std::to_string(seed) + " is listed twice: each repeat needs its own seed");
            e.seeds.push_back(seed);
        }
    }
    if (root["seed_path"]) e.seed_path = r.text(root["seed_path"], "seed_path");
    if (YAML::Node j = root["jitter"]) {
        if (!j.IsMap()) r.fail(j, "jitter: expected a map rig path -> half width (e.g. source.range_mm: 50)");
        for (const auto &kv : j) {
            const std::string path = r.text(kv.first, "jitter (a rig path)");
            const double w = r.number(kv.second, "jitter." + path);
            if (w < 0) r.fail(kv.second, "jitter." + path + " = " + num(w) + ": expected a half width >= 0");
            e.jitter.emplace_back(path, w);
        }
    }
}

// Calibration per configuration: exact, or from board pairs.
void readCalibration(Experiment &e, const YAML::Node &root, const Reader &r) {
    if (YAML::Node c = root["calibration"]) {
        e.calibration = r.text(c, "calibration");
        if (e.calibration != "exact" && e.calibration != "board")
            r.fail(c, "calibration: '" + e.calibration + "': expected exact (the source's own) or board (calibrated per test)");
    }
    if (YAML::Node b = root["board_calibration"]) {
        if (!b.IsMap()) r.fail(b, "board_calibration: expected {pairs, board, square_mm, capture}");
        r.checkKeys(b, {"pairs", "board", "square_mm", "capture", "max_frames"}, "board_calibration");
        auto &spec = e.board_calibration;
        if (b["pairs"]) spec.pairs = static_cast<int>(wholeNumber(r, b["pairs"], "board_calibration.pairs", 4, 1000));
        if (b["max_frames"]) spec.max_frames = static_cast<int>(wholeNumber(r, b["max_frames"], "board_calibration.max_frames", 1, 100000));
        const std::string board = b["board"] ? r.text(b["board"], "board_calibration.board") : "9x6";
        const double square = b["square_mm"] ? r.number(b["square_mm"], "board_calibration.square_mm") : 25.0;
        try {
            spec.board = BoardSpec::parse(board, square);
        } catch (const Error &x) {
            r.fail(b, std::string("board_calibration: ") + x.what());
        }
        if (YAML::Node cap = b["capture"]) {
            if (!cap.IsMap()) r.fail(cap, "board_calibration.capture: expected a map of rig paths to values");
            for (const auto &kv : cap) spec.capture.emplace_back(r.text(kv.first, "board_calibration.capture (a rig path)"), yamlText(kv.second));
        }
    }
    if (e.calibration == "board" && e.board_calibration.capture.empty())
        r.fail(root["calibration"], "calibration: board needs board_calibration.capture: the rig settings that make the "
                                    "source show a chessboard (see configs/experiments/e1.yaml)");
}

// The lens table: focal length -> rig overrides of that lens.
void readLensTable(Experiment &e, const YAML::Node &root, const Reader &r) {
    YAML::Node lt = root["lens_table"];
    if (!lt) return;
    fs::path lp = r.text(lt, "lens_table");
    if (lp.is_relative()) lp = fs::path(e.file).parent_path() / lp;
    e.lens_table_file = lp.lexically_normal().string();
    if (!fs::exists(e.lens_table_file)) r.fail(lt, "lens_table: file '" + e.lens_table_file + "' does not exist");
    // The one YAML loader: size bound, duplicate keys and syntax errors with line and column.
    const YAML::Node table = loadYaml(e.lens_table_file);
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
            for (const auto &kv : st) l.set.emplace_back(lr.text(kv.first, "lenses.set (a rig path)"), yamlText(kv.second));
        }
        e.lens_table.push_back(std::move(l));
    }
    if (!root["lenses_mm"])
        for (const auto &l : e.lens_table) e.lenses_mm.push_back(l.focal_length_mm);
}

// Where each variable goes: the plugins' settings of its name, or `bind:`.
void readBind(Experiment &e, const YAML::Node &root, const Reader &r, const PluginHost &host) {
    e.bind = defaultBind(e.rig, host);
    YAML::Node b = root["bind"];
    if (!b) return;
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

// The number at a dotted rig path whose list indices are in range, or nothing.
std::optional<double> rigNumber(const YAML::Node &rig, const std::string &path) {
    YAML::Node n = YAML::Clone(rig);
    std::stringstream ss(path);
    for (std::string part; std::getline(ss, part, '.');) {
        if (!n.IsDefined() || n.IsNull() || n.IsScalar()) return std::nullopt;
        int64_t index = 0;
        if (n.IsSequence() && !input::parseInteger(part, index, nullptr, 0, static_cast<int64_t>(n.size()) - 1)) return std::nullopt;
        n = n.IsSequence() ? n[static_cast<size_t>(index)] : n[part];
    }
    double v = 0;
    if (n.IsDefined() && n.IsScalar() && sdk::parseDecimalReal(n.Scalar(), v)) return v;
    return std::nullopt;
}

// Defaults of the variables: the experiment's `defaults:`, else the base rig's values.
struct Defaults {
    TestGeometry geometry;
    std::set<std::string> given;
};

Defaults readDefaults(Experiment &e, const YAML::Node &root, const Reader &r, const PluginHost &host) {
    Defaults out;
    for (const auto &var : kVariables) {
        const auto &paths = e.bind[var];
        if (paths.empty()) continue;
        // As the rig states it, else the default of the plugin's setting: never 0 for a
        // value nobody gave (a sim source refuses camera_height_mm 0, and the message would
        // point at a rig that never says it).
        if (const auto v = rigNumber(e.rig, paths.front())) {
            *field(out.geometry, var) = *v;
            out.given.insert(var);
        } else if (const auto d = settingDefault(e.rig, paths.front(), host)) {
            *field(out.geometry, var) = *d;
        }
    }
    if (YAML::Node d = root["defaults"]) {
        if (!d.IsMap()) r.fail(d, "defaults: expected a map of variables");
        r.checkKeys(d, kVariables, "defaults");
        for (const auto &kv : d) {
            const std::string var = Reader::key(kv.first);
            *field(out.geometry, var) = r.number(kv.second, "defaults." + var);
            out.given.insert(var);
        }
    }
    return out;
}

// One entry of `tests:`, its rig validated against the plugins.
ExperimentTest readTest(const Experiment &e, const YAML::Node &root, const YAML::Node &tn, size_t i, const Defaults &defaults,
                        std::set<std::string> &ids, const Reader &r, const PluginHost &host) {
    const std::string at = "tests[" + std::to_string(i) + "]";
    if (!tn.IsMap()) r.fail(tn, at + ": expected a map (id, baseline_mm, focal_length_mm, range_mm, ...)");
    r.checkKeys(tn, kTestKeys, at);
    ExperimentTest t;
    t.id = tn["id"] ? r.text(tn["id"], at + ".id") : std::to_string(i + 1);
    t.line = tn.Mark().line + 1;
    // The id names the folder test_<id>/ under --out: it must stay a file name.
    if (std::string why; !input::isSafeName(t.id, &why))
        r.fail(tn["id"], at + ".id '" + sdk::printable(t.id) + "': " + why + " (it names the folder test_<id>/ under --out)");
    if (!ids.insert(t.id).second) r.fail(tn, "test " + t.id + ": id used twice");
    t.geometry = defaults.geometry;
    for (const auto &var : kVariables) {
        if (tn[var]) {
            *field(t.geometry, var) = r.number(tn[var], "test " + t.id + ": " + var);
        } else if (!defaults.given.count(var) && var != "inclination_deg" && var != "camera_height_mm" && !e.dataset_tests) {
            r.fail(tn, "test " + t.id + ": no " + var + " (set it in the test, in defaults:, or in the base rig)");
        }
    }
    if (YAML::Node s = tn["set"]) {
        if (!s.IsMap()) r.fail(s, "test " + t.id + ": set: expected a map of rig paths to values");
        for (const auto &kv : s) t.set.emplace_back(r.text(kv.first, "test " + t.id + ": set"), yamlText(kv.second));
    }
    if (tn["repeats"]) t.repeats = static_cast<int>(wholeNumber(r, tn["repeats"], "test " + t.id + ": repeats", 1, 10000));
    if (YAML::Node pp = tn["paper"]) {
        if (!pp.IsMap()) r.fail(pp, "test " + t.id + ": paper: expected a map figure -> value the paper reported");
        for (const auto &kv : pp)
            t.paper.emplace_back(r.text(kv.first, "test " + t.id + ": paper"),
                                 r.number(kv.second, "test " + t.id + ": paper." + Reader::key(kv.first)));
    }
    if (!e.seeds.empty() && static_cast<int>(e.seeds.size()) < e.repeatsOf(t))
        r.fail(root["seeds"], "seeds: " + std::to_string(e.seeds.size()) + " seeds for " + std::to_string(e.repeatsOf(t)) +
                                  " repeats of test " + t.id + ": give one seed per repeat");
    if (!e.lens_table.empty() && !lensFor(e, t.geometry.focal_length_mm))
        r.fail(tn, "test " + t.id + ": focal_length_mm = " + num(t.geometry.focal_length_mm) + ": not in the lens table " +
                       e.lens_table_file);
    if (!e.dataset_tests) checkGeometry(e, t, r, tn); // a dataset's scene has no geometry to check
    // The whole rig of this test must be valid before anything runs.
    try {
        rigFromNode(rigForTest(e, t, 0), e.rig_file, host);
    } catch (const Error &x) {
        r.fail(tn, "test " + t.id + ": its rig is invalid: " + x.what());
    }
    return t;
}

void readTests(Experiment &e, const YAML::Node &root, const Reader &r, const PluginHost &host) {
    const Defaults defaults = readDefaults(e, root, r, host);
    const YAML::Node tests = e.dataset_tests ? datasetTests(root, r) : root["tests"];
    if (!tests || !tests.IsSequence() || tests.size() == 0) throw Error(e.file + ": missing key 'tests' (a list of tests)");
    std::set<std::string> ids;
    for (size_t i = 0; i < tests.size(); ++i) {
        e.tests.push_back(readTest(e, root, tests[i], i, defaults, ids, r, host));
    }
}

void readCharts(Experiment &e, const YAML::Node &root, const Reader &r) {
    const YAML::Node c = root["charts"];
    if (!c) {
        e.charts = {{"bars", "eta_3d_percent", "", e.name + ": stereo efficiency η3D per test", "eta_3d_bars", {70}},
                    {"bars", "eta_2d_percent", "", e.name + ": planar efficiency η2D per test", "eta_2d_bars", {70}},
                    {"scatter", "eta_3d_percent", "form_factor", e.name + ": η3D against the form factor FF", "eta_3d_vs_ff", {}}};
        return;
    }
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
            r.fail(cn["file"] ? cn["file"] : cn, "charts.file '" + sdk::printable(s.file) + "': " + why +
                                                     " (the chart's file name under --out, without extension)");
        if (cn["reference_lines"]) s.reference_lines = r.numbers(cn["reference_lines"], "charts.reference_lines");
        e.charts.push_back(s);
    }
}

Experiment loadWith(const std::string &file, const PluginHost &host, const std::vector<std::string> &overrides) {
    std::error_code ec;
    Experiment e;
    e.file = fs::absolute(file, ec).lexically_normal().string();
    e.overrides = overrides;
    const YAML::Node root = readRoot(e, file, overrides);
    const Reader r{e.file};
    r.checkKeys(root, kTopKeys, "experiment");
    e.name = root["name"] ? r.text(root["name"], "name") : fs::path(e.file).stem().string();
    // The name makes the default output folder out/<name>: it must stay one file name.
    if (std::string why; !input::isSafeName(e.name, &why))
        r.fail(root["name"], "name '" + sdk::printable(e.name) + "': " + why + " (it names the default output folder out/<name>)");
    e.description = root["description"] ? r.text(root["description"], "description") : "";
    readRig(e, root, r);
    readHead(e, root, r, host);
    readRepeats(e, root, r);
    readCalibration(e, root, r);
    readLensTable(e, root, r);
    readBind(e, root, r, host);
    e.dataset_tests = root["dataset"].IsDefined();
    readTests(e, root, r, host);
    readCharts(e, root, r);
    return e;
}

} // namespace

Experiment loadExperiment(const std::string &file, const PluginHost &host, const std::vector<std::string> &overrides) {
    Experiment e;
    try {
        e = loadWith(file, host, overrides);
    } catch (const OverrideError &) {
        throw;
    } catch (const Error &x) {
        if (overrides.empty()) throw;
        // Valid as written, refused with the --set values: the mistake is on the command
        // line (exit status 2), whatever part of the file the message names.
        try {
            loadWith(file, host, {});
        } catch (const Error &) {
            throw x;
        }
        std::string given;
        for (const auto &o : overrides) given += " --set " + o;
        throw OverrideError(std::string(x.what()) + " (the file is valid without" + given + ")");
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
    e.rig = loadYaml(e.rig_file);
    e.rig_text = readTextFile(e.rig_file);
    checkRigShape(e.rig, e.rig_file, "--rig");
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

} // namespace binocle
