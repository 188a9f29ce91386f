// SPDX-License-Identifier: MIT
// The rig of one test: the base rig with the test's lens, variables, overrides, seed and
// jitter applied; and where the variables go when the experiment does not say.
#include "experiment/test_rig.hpp"

#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "host/plugin_kinds.hpp"
#include "input/yaml_file.hpp"

#include <binocle/numbers.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include <spdlog/spdlog.h>

namespace binocle {
namespace experiment {

const std::vector<std::string> kVariables = {"baseline_mm", "focal_length_mm", "range_mm", "camera_height_mm",
                                             "inclination_deg"};

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

double valueOf(const TestGeometry &g, const std::string &name) {
    TestGeometry copy = g;
    const double *v = field(copy, name);
    return v ? *v : NAN;
}

namespace {

// The settings table of the plugin a rig block names; empty when the block or the plugin
// is missing (the rig's own validation says so, with its position).
std::vector<binocle_param_desc> settingsOf(const YAML::Node &block, int32_t kind, const PluginHost &host) {
    // IsDefined first: IsMap() on a key a map lacks throws yaml-cpp's "invalid node".
    if (!block.IsDefined() || !block.IsMap() || !block["plugin"] || !block["plugin"].IsScalar()) return {};
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
// The answer points into the table: a temporary table would be gone before it is read.
const binocle_param_desc *setting(std::vector<binocle_param_desc> &&table, const std::string &name) = delete;

} // namespace

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
    if (source.IsDefined() && source.IsMap() && source[key] && YAML::convert<double>::decode(source[key], v)) return v;
    const auto table = settingsOf(source, BINOCLE_KIND_STEREO_SOURCE, host);
    const auto *d = setting(table, key);
    if (d && d->default_value) {
        try {
            if (YAML::convert<double>::decode(YAML::Load(d->default_value), v)) return v;
        } catch (const YAML::Exception &) {
        }
    }
    return 0;
}

std::optional<double> settingDefault(const YAML::Node &rig, const std::string &path, const PluginHost &host) {
    const auto dot = path.rfind('.');
    if (dot == std::string::npos) return std::nullopt;
    const std::string top = path.substr(0, path.find('.'));
    int32_t kind = -1; // the kind whose rig key `top` is
    for (const PluginKind *k : pluginKinds())
        if (top == k->rigKey) kind = k->kind;
    if (kind < 0) return std::nullopt;
    const auto table = settingsOf(nodeAt(rig, path.substr(0, dot)), kind, host);
    const auto *d = setting(table, path.substr(dot + 1));
    double v = 0;
    if (d && d->default_value && sdk::parseDecimalReal(d->default_value, v)) return v;
    return std::nullopt;
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

namespace {

// Uniform in [-1, 1) from a seed and a stream number, the same on every platform
// (std::uniform_real_distribution is not specified bit for bit).
double jitterUnit(uint32_t seed, uint32_t stream) {
    std::seed_seq seq{seed, stream, 0x6a177e2u};
    std::mt19937 gen(seq);
    return static_cast<double>(gen()) / 2147483648.0 - 1.0;
}

} // namespace

const Lens *lensFor(const Experiment &e, double focal_length_mm) {
    for (const auto &l : e.lens_table)
        if (std::fabs(l.focal_length_mm - focal_length_mm) < 1e-6) return &l;
    return nullptr;
}

} // namespace experiment

using namespace experiment;

uint32_t Experiment::seedOf(int repeat) const {
    if (!seeds.empty()) return seeds.at(static_cast<size_t>(repeat));
    return seed + static_cast<uint32_t>(repeat);
}

YAML::Node rigForTest(const Experiment &e, const ExperimentTest &t, int repeat) {
    YAML::Node rig;
    if (e.rig_text.empty()) { // an experiment built in code
        rig = YAML::Clone(e.rig);
    } else {
        rig = input::parseYaml(e.rig_text, e.rig_file); // read once at load: it parsed then
        for (const auto &[path, value] : e.rig_set) applyOverride(rig, Override{path, value, "rig_set: " + path});
    }
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

} // namespace binocle
