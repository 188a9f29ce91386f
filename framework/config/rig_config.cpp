// SPDX-License-Identifier: MIT
// Rig descriptions in YAML: loading, overrides, validation against plugin tables.
#include "config/rig_config.hpp"

#include "core/error.hpp"
#include "input/numbers.hpp"
#include "input/text.hpp"
#include "input/yaml_file.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

namespace fs = std::filesystem;

namespace binocle {

std::string Location::str() const {
    if (!override.empty()) return "command line --set " + override;
    std::string s = file;
    if (line > 0) s += ":" + std::to_string(line) + ":" + std::to_string(column);
    return s;
}

Override Override::parse(const std::string &text) {
    const auto eq = text.find('=');
    if (eq == std::string::npos || eq == 0)
        throw Error("--set " + text + ": expected KEY=VALUE, e.g. --set matcher.num_disparities=128");
    Override o;
    o.path = text.substr(0, eq);
    o.value = text.substr(eq + 1);
    o.text = text;
    return o;
}

namespace {

std::vector<std::string> splitPath(const std::string &path) {
    std::vector<std::string> parts;
    std::string cur;
    for (char c : path) {
        if (c == '.' || c == '[' || c == ']') {
            if (!cur.empty()) parts.push_back(cur);
            cur.clear();
        } else {
            cur += c;
        }
    }
    if (!cur.empty()) parts.push_back(cur);
    return parts;
}

// Everything needed to say where a value came from.
struct Context {
    std::string file;
    std::string base_dir;
    std::vector<Override> overrides;

    Location at(const YAML::Node &node, const std::string &path) const {
        Location loc;
        loc.file = file;
        // The last --set that wrote this value or a block around it (`matcher={...}`
        // replaces the whole block: its keys come from the command line, not the file).
        for (auto o = overrides.rbegin(); o != overrides.rend(); ++o) {
            auto a = splitPath(o->path), b = splitPath(path);
            if (a.size() <= b.size() && std::equal(a.begin(), a.end(), b.begin())) {
                loc.override = o->text;
                return loc;
            }
        }
        if (node.IsDefined() && !node.Mark().is_null()) {
            loc.line = node.Mark().line + 1;
            loc.column = node.Mark().column + 1;
        }
        return loc;
    }
    [[noreturn]] void fail(const YAML::Node &node, const std::string &path, const std::string &what) const {
        throw Error(at(node, path).str() + ": " + path + ": " + what);
    }
};

// A value as it reads in a message: control characters escaped, long values cut.
std::string scalarText(const YAML::Node &n) {
    if (n.IsScalar()) return input::printable(n.Scalar());
    if (!n.IsDefined() || n.IsNull()) return "(nothing)";
    return n.IsMap() ? "(a map)" : "(a list)";
}

// A value as YAML text in flow style ("[1, 2]"): how lists reach the plugins.
std::string flowText(const YAML::Node &n) {
    YAML::Emitter e;
    e << YAML::Flow << n;
    return e.c_str();
}

// A map key as text; a non-scalar key (YAML allows "? [a, b]") is named, not converted.

std::string describeChoices(const binocle_param_desc &d) {
    std::string c = d.choices ? d.choices : "";
    std::replace(c.begin(), c.end(), '|', ',');
    return c;
}

std::string fmtNumber(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

// Parses and checks one value against its description; stores it in `out`.
void setValue(ParamValues &out, const binocle_param_desc &d, const YAML::Node &n, bool isExplicit, const Context &ctx,
              const std::string &path) {
    const std::string text = scalarText(n);
    auto bad = [&](const std::string &expected) {
        ctx.fail(n, path, "value '" + text + "' is not valid: expected " + expected);
    };
    auto checkRange = [&](double v, const char *kind) {
        if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) && v < d.min) bad(std::string(kind) + " >= " + fmtNumber(d.min));
        if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) && v > d.max) bad(std::string(kind) + " <= " + fmtNumber(d.max));
    };
    switch (d.type) {
    case BINOCLE_PARAM_BOOL: {
        bool v = false;
        if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) bad("true or false");
        out.setBool(d.name, v, isExplicit);
        break;
    }
    case BINOCLE_PARAM_INT: {
        long long v = 0;
        std::string what = "an integer";
        if (d.multiple_of > 0) what = "an integer multiple of " + std::to_string(d.multiple_of);
        if (d.flags & BINOCLE_PARAM_FLAG_ODD) what = "an odd integer";
        if (d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) what += " >= " + fmtNumber(d.min);
        if (d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) what += " <= " + fmtNumber(d.max);
        // One strict reader for the file and --set alike: decimal only ("0640" is not 416),
        // range-checked before any narrowing.
        std::string why;
        int64_t parsed = 0;
        if (!n.IsScalar() || !input::parseInteger(n.Scalar(), parsed, &why))
            bad(why.find("leading zeros") != std::string::npos || why.find("64 bits") != std::string::npos
                    ? what + " (" + why + ")"
                    : what);
        v = parsed;
        if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) && v < d.min) bad(what);
        if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) && v > d.max) bad(what);
        if ((d.flags & BINOCLE_PARAM_FLAG_ODD) && v % 2 == 0) bad(what);
        if (d.multiple_of > 0 && v % d.multiple_of != 0) bad(what);
        out.setInt(d.name, v, isExplicit);
        break;
    }
    case BINOCLE_PARAM_DOUBLE: {
        double v = 0;
        if (!n.IsScalar() || !input::parseReal(n.Scalar(), v)) bad("a decimal number");
        if (!std::isfinite(v)) bad("a finite number");
        checkRange(v, "a number");
        out.setDouble(d.name, v, isExplicit);
        break;
    }
    case BINOCLE_PARAM_ENUM: {
        std::string choices = d.choices ? d.choices : "";
        std::vector<std::string> list;
        std::stringstream ss(choices);
        for (std::string c; std::getline(ss, c, '|');) list.push_back(c);
        if (!n.IsScalar() || std::find(list.begin(), list.end(), n.Scalar()) == list.end()) {
            std::string hint = n.IsScalar() ? input::nearestWord(n.Scalar(), list) : "";
            bad("one of " + describeChoices(d) + (hint.empty() ? "" : " (did you mean '" + hint + "'?)"));
        }
        out.setText(d.name, d.type, n.Scalar(), isExplicit);
        break;
    }
    case BINOCLE_PARAM_STRING:
        if (!n.IsScalar()) bad("a string");
        out.setText(d.name, d.type, n.Scalar(), isExplicit);
        break;
    case BINOCLE_PARAM_PATH: {
        if (!n.IsScalar()) bad("a path");
        std::string p = n.Scalar();
        if (!p.empty() && fs::path(p).is_relative() && !ctx.base_dir.empty()) p = (fs::path(ctx.base_dir) / p).lexically_normal().string();
        out.setText(d.name, d.type, p, isExplicit);
        break;
    }
    case BINOCLE_PARAM_INT_LIST:
    case BINOCLE_PARAM_DOUBLE_LIST: {
        const bool ints = d.type == BINOCLE_PARAM_INT_LIST;
        const char *what = ints ? "a list of integers, e.g. [1, 2]" : "a list of numbers, e.g. [0.1, 0.2]";
        if (!n.IsSequence()) bad(what);
        for (const auto &e : n) {
            int64_t i = 0;
            double x = 0;
            if (!e.IsScalar() || (ints ? !input::parseInteger(e.Scalar(), i) : !input::parseReal(e.Scalar(), x)))
                bad(what);
        }
        out.setText(d.name, d.type, flowText(n), isExplicit);
        break;
    }
    case BINOCLE_PARAM_YAML: {
        YAML::Emitter e;
        e << n;
        out.setText(d.name, d.type, e.c_str(), isExplicit);
        break;
    }
    default: ctx.fail(n, path, "setting of unknown type " + std::to_string(d.type));
    }
}

// Keys of every plugin block besides the plugin's own settings.
const std::vector<std::string> kBlockKeys = {"plugin", "isolation", "call_timeout_ms", "restart", "max_restarts"};

// `isolation: process|none`, `call_timeout_ms`, `restart`, `max_restarts` of a block.
IsolationOptions isolationOf(const YAML::Node &node, const std::string &where, const Context &ctx) {
    IsolationOptions o;
    if (YAML::Node n = node["isolation"]) {
        if (!n.IsScalar() || (n.Scalar() != "process" && n.Scalar() != "none"))
            ctx.fail(n, where + ".isolation", "value '" + scalarText(n) + "' is not valid: expected process or none");
        o.process = n.Scalar() == "process";
    }
    auto integer = [&](const char *key, int32_t &v, int32_t least) {
        YAML::Node n = node[key];
        if (!n) return;
        long long x = 0;
        if (!n.IsScalar() || !YAML::convert<long long>::decode(n, x) || x < least || x > 3600000)
            ctx.fail(n, where + "." + key, "value '" + scalarText(n) + "' is not valid: expected an integer >= " +
                                               std::to_string(least));
        v = static_cast<int32_t>(x);
    };
    integer("call_timeout_ms", o.call_timeout_ms, 0);
    integer("max_restarts", o.max_restarts, 0);
    if (YAML::Node n = node["restart"]) {
        if (!n.IsScalar() || !YAML::convert<bool>::decode(n, o.restart))
            ctx.fail(n, where + ".restart", "value '" + scalarText(n) + "' is not valid: expected true or false");
    }
    if (!o.process && (node["call_timeout_ms"] || node["restart"] || node["max_restarts"]))
        ctx.fail(node, where, "call_timeout_ms, restart and max_restarts need isolation: process");
    return o;
}

ParamValues resolveWith(const PluginRecord &record, const YAML::Node &block, const std::string &where, const Context &ctx) {
    const auto descs = record.params();
    std::vector<std::string> names;
    for (const auto &d : descs) names.emplace_back(d.name);
    if (block.IsDefined() && !block.IsNull() && !block.IsMap())
        ctx.fail(block, where, "expected a map of settings for plugin '" + record.name + "'");
    if (block.IsMap()) {
        // The block's own keys (plugin, isolation, ...) are valid too, but the message lists the plugin's.
        YAML::Node settingsOnly(YAML::NodeType::Map);
        for (const auto &kv : block)
            if (!kv.first.IsScalar() || std::find(kBlockKeys.begin(), kBlockKeys.end(), kv.first.Scalar()) == kBlockKeys.end())
                settingsOnly.force_insert(kv.first, kv.second);
        if (auto unknown = input::findUnknownKey(settingsOnly, names, "for plugin '" + record.name + "'"))
            throw Error(ctx.at(unknown->key, where + "." + unknown->name).str() + ": " + where + ": " + unknown->message);
    }
    ParamValues values;
    for (const auto &d : descs) {
        const std::string path = where + "." + d.name;
        YAML::Node n = block.IsMap() ? block[d.name] : YAML::Node();
        if (n.IsDefined() && !n.IsNull()) {
            setValue(values, d, n, true, ctx, path);
        } else if (d.flags & BINOCLE_PARAM_FLAG_REQUIRED || !d.default_value) {
            ctx.fail(block, where, "missing key '" + std::string(d.name) + "' for plugin '" + record.name + "'" +
                                       (d.help && *d.help ? " (" + std::string(d.help) + ")" : ""));
        } else {
            YAML::Node def;
            try {
                def = YAML::Load(d.default_value);
            } catch (const YAML::Exception &) {
                def = YAML::Node(std::string(d.default_value));
            }
            Context pluginCtx{record.path, ctx.base_dir, {}};
            if (def.IsNull() && d.type != BINOCLE_PARAM_YAML) def = YAML::Node(std::string());
            setValue(values, d, def, false, pluginCtx, record.name + " default of " + d.name);
        }
    }
    return values;
}

const std::vector<std::string> kTopKeys = {"name", "description", "source", "calibration", "matcher",
                                           "transforms", "evaluators", "outputs", "runtime"};
const std::vector<std::string> kOutputKeys = {"disparity_png", "disparity_color", "disparity_pfm", "cloud_ply",
                                              "rectified_png", "max_range_mm"};

const std::vector<std::string> kRuntimeKeys = {"policy", "queue_depth", "matcher_instances", "on_source_error",
                                               "retry_for_s"};

RuntimeOptions runtimeBlock(const YAML::Node &r, const Context &ctx) {
    RuntimeOptions rt;
    if (!r.IsDefined() || r.IsNull()) return rt;
    if (!r.IsMap()) ctx.fail(r, "runtime", "expected a map (policy: lossless, queue_depth: 4, ...)");
    if (auto unknown = input::findUnknownKey(r, kRuntimeKeys))
        throw Error(ctx.at(unknown->key, "runtime." + unknown->name).str() + ": runtime: " + unknown->message);
    auto choice = [&](const char *key, const std::vector<std::string> &choices) -> std::optional<std::string> {
        YAML::Node n = r[key];
        if (!n || n.IsNull()) return std::nullopt;
        if (n.IsScalar() && std::find(choices.begin(), choices.end(), n.Scalar()) != choices.end()) return n.Scalar();
        std::string all, hint = n.IsScalar() ? input::nearestWord(n.Scalar(), choices) : "";
        for (const auto &c : choices) all += (all.empty() ? "" : ", ") + c;
        ctx.fail(n, std::string("runtime.") + key, "value '" + scalarText(n) + "' is not valid: expected one of " + all +
                                                      (hint.empty() ? "" : " (did you mean '" + hint + "'?)"));
    };
    auto integer = [&](const char *key, int &out, int lo, int hi) {
        YAML::Node n = r[key];
        if (!n || n.IsNull()) return;
        long long v = 0;
        bool ok = n.IsScalar();
        if (ok) {
            try {
                size_t used = 0;
                v = std::stoll(n.Scalar(), &used, 10);
                ok = used == n.Scalar().size();
            } catch (const std::logic_error &) {
                ok = false;
            }
        }
        if (!ok || v < lo || v > hi)
            ctx.fail(n, std::string("runtime.") + key, "value '" + scalarText(n) + "' is not valid: expected an integer >= " +
                                                          std::to_string(lo) + " <= " + std::to_string(hi));
        out = static_cast<int>(v);
    };
    if (auto p = choice("policy", {"lossless", "latest"}))
        rt.policy = *p == "latest" ? RuntimeOptions::Policy::Latest : RuntimeOptions::Policy::Lossless;
    integer("queue_depth", rt.queue_depth, 1, 1024);
    integer("matcher_instances", rt.matcher_instances, 1, 64);
    if (auto e = choice("on_source_error", {"stop", "retry"}))
        rt.on_source_error = *e == "retry" ? RuntimeOptions::OnSourceError::Retry : RuntimeOptions::OnSourceError::Stop;
    if (YAML::Node n = r["retry_for_s"]; n && !n.IsNull()) {
        double v = 0;
        if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v) || !(v > 0))
            ctx.fail(n, "runtime.retry_for_s", "value '" + scalarText(n) + "' is not valid: expected a positive number of seconds");
        if (rt.on_source_error != RuntimeOptions::OnSourceError::Retry)
            ctx.fail(n, "runtime.retry_for_s", "is only used with on_source_error: retry (on_source_error is stop)");
        rt.retry_for_s = v;
    }
    return rt;
}

PluginBlock block(const YAML::Node &node, const std::string &where, int32_t kind, const PluginHost &host,
                  const Context &ctx) {
    if (!node.IsDefined() || node.IsNull()) throw Error(ctx.file + ": missing block '" + where + "' (with a 'plugin:' key)");
    if (!node.IsMap()) ctx.fail(node, where, std::string("expected a map with 'plugin: <name>' and the plugin's settings"));
    YAML::Node p = node["plugin"];
    if (!p.IsDefined() || !p.IsScalar()) ctx.fail(node, where, std::string("missing key 'plugin' (the ") + kindName(kind) + " plugin's name)");
    PluginBlock b;
    b.where = where;
    b.plugin = p.Scalar();
    b.location = ctx.at(node, where);
    // Opens binocle_<name>.so only; the whole search path is examined (in children) only
    // to say what else there is. An isolated plugin is read by a helper process: none of
    // its code runs in this one, not even its library's constructors.
    const IsolationOptions isolation = isolationOf(node, where, ctx);
    b.record = isolation.process ? host.describe(b.plugin, kind) : host.lookup(b.plugin, kind);
    if (!b.record) {
        host.scan(ScanMode::Isolated);
        std::vector<std::string> names;
        for (const auto &r : host.plugins())
            if (r.kind == kind) names.push_back(r.name);
        std::string hint = input::nearestWord(b.plugin, names), all;
        for (const auto &n : names) all += (all.empty() ? "" : ", ") + n;
        std::string refused;
        for (const auto &r : host.refused())
            if (fs::path(r.path).stem().string() == "binocle_" + b.plugin) refused = "; " + r.path + " was refused: " + r.reason;
        ctx.fail(p, where + ".plugin", std::string("no ") + kindName(kind) + " plugin named '" + b.plugin + "'" +
                                           (hint.empty() ? "" : "; did you mean '" + hint + "'?") +
                                           " (available: " + (all.empty() ? "none" : all) + ")" + refused);
    }
    b.params = resolveWith(*b.record, node, where, ctx);
    b.params.setIsolation(isolation);
    return b;
}

std::vector<PluginBlock> blockList(const YAML::Node &node, const std::string &where, int32_t kind, const PluginHost &host,
                                   const Context &ctx) {
    std::vector<PluginBlock> out;
    if (!node.IsDefined() || node.IsNull()) return out;
    if (!node.IsSequence()) ctx.fail(node, where, "expected a list of plugin blocks (- plugin: <name> ...)");
    for (size_t i = 0; i < node.size(); ++i)
        out.push_back(block(node[i], where + "[" + std::to_string(i) + "]", kind, host, ctx));
    return out;
}

RigConfig build(const YAML::Node &root, const Context &ctx, const PluginHost &host) {
    if (!root.IsMap()) throw Error(ctx.file + ": expected a YAML map with source, matcher, ... at the top level");
    if (auto unknown = input::findUnknownKey(root, kTopKeys))
        throw Error(ctx.at(unknown->key, unknown->name).str() + ": " + unknown->message);
    RigConfig rig;
    rig.file = ctx.file;
    rig.base_dir = ctx.base_dir;
    if (YAML::Node n = root["name"]; n.IsDefined() && !n.IsNull()) {
        if (!n.IsScalar()) ctx.fail(n, "name", "value " + scalarText(n) + " is not valid: expected a text");
        rig.name = n.Scalar();
    } else {
        rig.name = fs::path(ctx.file).stem().string();
    }
    rig.source = block(root["source"], "source", BINOCLE_KIND_STEREO_SOURCE, host, ctx);
    rig.matcher = block(root["matcher"], "matcher", BINOCLE_KIND_MATCHER, host, ctx);
    rig.transforms = blockList(root["transforms"], "transforms", BINOCLE_KIND_CLOUD_TRANSFORM, host, ctx);
    rig.evaluators = blockList(root["evaluators"], "evaluators", BINOCLE_KIND_EVALUATOR, host, ctx);
    if (YAML::Node c = root["calibration"]; c.IsDefined() && !c.IsNull()) {
        if (!c.IsScalar()) ctx.fail(c, "calibration", "expected the path of a calibration file (OpenCV FileStorage YAML)");
        fs::path p = c.Scalar();
        if (p.is_relative()) p = fs::path(ctx.base_dir) / p;
        if (!fs::exists(p)) ctx.fail(c, "calibration", "file '" + p.string() + "' does not exist");
        rig.calibration_file = p.lexically_normal().string();
    }
    if (YAML::Node o = root["outputs"]; o.IsDefined() && !o.IsNull()) {
        if (!o.IsMap()) ctx.fail(o, "outputs", "expected a map (disparity_png: true, ...)");
        if (auto unknown = input::findUnknownKey(o, kOutputKeys))
            throw Error(ctx.at(unknown->key, "outputs." + unknown->name).str() + ": outputs: " + unknown->message);
        auto flag = [&](const char *key, bool &v) {
            YAML::Node n = o[key];
            if (!n) return;
            if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
                ctx.fail(n, std::string("outputs.") + key, "value '" + scalarText(n) + "' is not valid: expected true or false");
        };
        flag("disparity_png", rig.outputs.disparity_png);
        flag("disparity_color", rig.outputs.disparity_color);
        flag("disparity_pfm", rig.outputs.disparity_pfm);
        flag("cloud_ply", rig.outputs.cloud_ply);
        flag("rectified_png", rig.outputs.rectified_png);
        if (YAML::Node n = o["max_range_mm"]) {
            double v = 0;
            if (!n.IsScalar() || !input::parseReal(n.Scalar(), v) || !(v > 0))
                ctx.fail(n, "outputs.max_range_mm", "value '" + scalarText(n) + "' is not valid: expected a positive number of mm");
            rig.outputs.max_range_mm = v;
        }
    }
    rig.runtime = runtimeBlock(root["runtime"], ctx);
    YAML::Emitter e;
    e << root;
    rig.resolved_yaml = e.c_str();
    return rig;
}

RigConfig rigFromTree(YAML::Node root, const std::string &file, const std::vector<Override> &overrides,
                      const PluginHost &host) {
    for (const auto &o : overrides) applyOverride(root, o);
    Context ctx{file, fs::path(file).parent_path().string(), overrides};
    return build(root, ctx, host);
}

} // namespace

void applyOverride(YAML::Node &root, const Override &o) {
    const auto parts = splitPath(o.path);
    if (parts.empty()) throw Error("--set " + o.text + ": empty key");
    YAML::Node value;
    try {
        value = input::parseYaml(o.value, "--set " + o.text);
    } catch (const input::YamlError &e) {
        throw Error(e.what());
    }
    // A list index: decimal, within the list; checked before any conversion.
    auto index = [&](const YAML::Node &list, const std::string &part) -> size_t {
        int64_t i = 0;
        const int64_t last = static_cast<int64_t>(list.size()) - 1;
        if (!input::parseInteger(part, i, nullptr, 0, last))
            throw Error("--set " + o.text + ": '" + input::printable(part) + "' is not an index of the list (" +
                        (last < 0 ? std::string("the list is empty") : "0.." + std::to_string(last)) + ")");
        return static_cast<size_t>(i);
    };
    // Walk with fresh handles: yaml-cpp node assignment would rebind, not descend.
    std::vector<YAML::Node> chain{root};
    for (size_t i = 0; i + 1 < parts.size(); ++i) {
        YAML::Node cur = chain.back();
        YAML::Node next;
        if (cur.IsSequence()) {
            next = cur[index(cur, parts[i])];
        } else if (cur.IsMap() || cur.IsNull() || !cur.IsDefined()) {
            next = cur[parts[i]];
            if (!next.IsDefined() || next.IsNull()) {
                cur[parts[i]] = YAML::Node(YAML::NodeType::Map);
                next = cur[parts[i]];
            }
        } else {
            throw Error("--set " + o.text + ": '" + parts[i] + "' leads into a scalar value");
        }
        chain.push_back(next);
    }
    YAML::Node last = chain.back();
    if (last.IsSequence()) {
        last[index(last, parts.back())] = value;
    } else if (last.IsScalar()) {
        throw Error("--set " + o.text + ": the parent of '" + parts.back() + "' is a scalar value");
    } else {
        last[parts.back()] = value;
    }
}

RigConfig loadRig(const std::string &file, const std::vector<Override> &overrides, const PluginHost &host) {
    std::error_code ec;
    const std::string abs = fs::absolute(file, ec).lexically_normal().string();
    if (!fs::exists(abs)) throw Error("rig file " + file + " does not exist");
    YAML::Node root;
    try {
        root = input::loadYamlFile(abs);
    } catch (const input::YamlError &e) {
        throw Error(e.what());
    }
    return rigFromTree(root, abs, overrides, host);
}

RigConfig loadRigText(const std::string &text, const std::string &file, const std::vector<Override> &overrides,
                      const PluginHost &host) {
    YAML::Node root;
    try {
        root = input::parseYaml(text, file);
    } catch (const input::YamlError &e) {
        throw Error(e.what());
    }
    return rigFromTree(root, file, overrides, host);
}

RigConfig rigFromNode(const YAML::Node &root, const std::string &file, const PluginHost &host) {
    Context ctx{file, fs::path(file).parent_path().string(), {}};
    return build(root, ctx, host);
}

ParamValues resolveParams(const PluginRecord &record, const YAML::Node &block, const std::string &where,
                          const std::string &file, const std::string &base_dir) {
    Context ctx{file, base_dir, {}};
    return resolveWith(record, block, where, ctx);
}

ParamValues paramsFromYaml(const PluginRecord &record, const std::string &yaml) {
    YAML::Node n = YAML::Load(yaml);
    std::error_code ec;
    return resolveParams(record, n, record.name, "(inline YAML)", fs::current_path(ec).string());
}

} // namespace binocle
