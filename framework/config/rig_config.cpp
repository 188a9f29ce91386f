// SPDX-License-Identifier: MIT
// Rig descriptions in YAML: loading, overrides, validation against plugin tables.
#include "config/rig_config.hpp"

#include "core/error.hpp"
#include "host/plugin_kinds.hpp"
#include "input/integer_range.hpp"
#include "input/names.hpp"
#include "input/yaml_file.hpp"

#include <binocle/settings.hpp>
#include <binocle/text.hpp>

#include <algorithm>
#include <iterator>
#include <cmath>
#include <filesystem>
#include <sstream>

namespace fs = std::filesystem;

namespace binocle {

const std::vector<PluginBlock> &RigConfig::blocks(int32_t kind) const {
    static const std::vector<PluginBlock> none;
    const auto it = plugins.find(kind);
    return it == plugins.end() ? none : it->second;
}

std::string Location::str() const {
    if (!override.empty()) return "command line --set " + override;
    std::string s = file;
    if (line > 0) s += ":" + std::to_string(line) + ":" + std::to_string(column);
    return s;
}

Override Override::parse(const std::string &text) {
    const auto eq = text.find('=');
    if (eq == std::string::npos || eq == 0)
        throw OverrideError("--set " + text + ": expected KEY=VALUE, e.g. --set matcher.num_disparities=128");
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
        raise(at(node, path), path + ": " + what);
    }
    // A value from --set is a mistake on the command line; from the file, in the file.
    [[noreturn]] void raise(const Location &loc, const std::string &message) const {
        if (!loc.override.empty()) throw OverrideError(loc.str() + ": " + message);
        throw Error(loc.str() + ": " + message);
    }
};

// A value as it reads in a message: control characters escaped, long values cut.
std::string scalarText(const YAML::Node &n) {
    if (n.IsScalar()) return sdk::printable(n.Scalar());
    if (!n.IsDefined() || n.IsNull()) return "(nothing)";
    return n.IsMap() ? "(a map)" : "(a list)";
}

// A value as YAML text in flow style ("[1, 2]"): how lists reach the plugins.
std::string flowText(const YAML::Node &n) {
    YAML::Emitter e;
    e << YAML::Flow << n;
    return e.c_str();
}

// One scalar through the SDK's settings checker (binocle/settings.hpp), the one home of
// what a setting accepts: plugin settings, `runtime:`, `outputs:`, isolation keys and
// --set values all read here, so the same text gets the same answer everywhere.
sdk::SettingValue readScalar(const binocle_param_desc &d, const YAML::Node &n, const Context &ctx,
                             const std::string &path) {
    sdk::SettingValue v;
    // An empty value (`key:`, `--set key=`, null, ~) is the empty text: the checker takes it
    // where a setting accepts it (a string, a path) and refuses it everywhere else; it
    // never stands for the plugin's default.
    const sdk::SettingProblem why = n.IsScalar() ? sdk::readSetting(d, n.Scalar(), v)
                                    : n.IsNull() ? sdk::readSetting(d, "", v)
                                                 : sdk::SettingProblem{"is not a scalar", sdk::settingExpects(d)};
    if (why) {
        const std::string hint =
            d.type == BINOCLE_PARAM_ENUM && n.IsScalar() ? input::nearestWord(n.Scalar(), sdk::settingChoices(d)) : "";
        ctx.fail(n, path, "value '" + scalarText(n) + "' is not valid: expected " + why.expected +
                              (hint.empty() ? "" : " (did you mean '" + hint + "'?)"));
    }
    return v;
}

// Parses and checks one value against its description; stores it in `out`.
void setValue(ParamValues &out, const binocle_param_desc &d, const YAML::Node &n, bool isExplicit, const Context &ctx,
              const std::string &path) {
    auto bad = [&](const std::string &expected) {
        ctx.fail(n, path, "value '" + scalarText(n) + "' is not valid: expected " + expected);
    };
    switch (d.type) {
    case BINOCLE_PARAM_BOOL: out.setBool(d.name, readScalar(d, n, ctx, path).boolean, isExplicit); break;
    case BINOCLE_PARAM_INT: out.setInt(d.name, readScalar(d, n, ctx, path).integer, isExplicit); break;
    case BINOCLE_PARAM_DOUBLE: out.setDouble(d.name, readScalar(d, n, ctx, path).real, isExplicit); break;
    case BINOCLE_PARAM_ENUM:
    case BINOCLE_PARAM_STRING: out.setText(d.name, d.type, readScalar(d, n, ctx, path).text, isExplicit); break;
    case BINOCLE_PARAM_PATH: {
        std::string p = readScalar(d, n, ctx, path).text;
        if (!p.empty() && fs::path(p).is_relative() && !ctx.base_dir.empty()) p = (fs::path(ctx.base_dir) / p).lexically_normal().string();
        out.setText(d.name, d.type, p, isExplicit);
        break;
    }
    case BINOCLE_PARAM_INT_LIST:
    case BINOCLE_PARAM_DOUBLE_LIST: {
        // Each element by the same reader, checked as the flow text the plugin receives.
        if (!n.IsSequence()) bad(sdk::settingExpects(d));
        for (const auto &e : n)
            if (!e.IsScalar()) bad(sdk::settingExpects(d));
        sdk::SettingValue v;
        if (const sdk::SettingProblem why = sdk::readSetting(d, flowText(n), v)) bad(why.expected);
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

// The keys of a block besides the plugin's settings, described as settings are.
const binocle_param_desc kIsolationKeys[] = {
    sdk::Param::choice("isolation", "none", "process|none"),
    sdk::Param::integer("call_timeout_ms", "0").min(0).max(3600000),
    sdk::Param::boolean("restart", false),
    sdk::Param::integer("max_restarts", "3").min(0).max(3600000),
};

// `isolation: process|none`, `call_timeout_ms`, `restart`, `max_restarts` of a block.
IsolationOptions isolationOf(const YAML::Node &node, const std::string &where, const Context &ctx) {
    IsolationOptions o;
    auto read = [&](const binocle_param_desc &d) -> std::optional<sdk::SettingValue> {
        YAML::Node n = node[d.name];
        if (!n) return std::nullopt;
        return readScalar(d, n, ctx, where + "." + d.name);
    };
    if (auto v = read(kIsolationKeys[0])) o.process = v->text == "process";
    if (auto v = read(kIsolationKeys[1])) o.call_timeout_ms = static_cast<int32_t>(v->integer);
    if (auto v = read(kIsolationKeys[2])) o.restart = v->boolean;
    if (auto v = read(kIsolationKeys[3])) o.max_restarts = static_cast<int32_t>(v->integer);
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
            ctx.raise(ctx.at(unknown->key, where + "." + unknown->name), where + ": " + unknown->message);
    }
    ParamValues values;
    for (const auto &d : descs) {
        const std::string path = where + "." + d.name;
        YAML::Node n = block.IsMap() ? block[d.name] : YAML::Node();
        // A key given with no value is given: checked as the empty text (readScalar), not
        // the default. A YAML setting's null is a value of its own.
        if (n.IsDefined()) {
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

// The keys of a rig's top level: its own, and every plugin kind's rig key.
std::vector<std::string> topKeys() {
    std::vector<std::string> keys = {"name", "description"};
    for (const PluginKind *k : pluginKinds()) keys.emplace_back(k->rigKey);
    keys.insert(keys.end(), {"calibration", "outputs", "runtime"});
    return keys;
}
// `outputs:`, described as settings are; the order is the one build() reads them in.
const binocle_param_desc kOutputKeys[] = {
    sdk::Param::boolean("disparity_png", true), sdk::Param::boolean("disparity_color", true),
    sdk::Param::boolean("disparity_pfm", false), sdk::Param::boolean("cloud_ply", true),
    sdk::Param::boolean("rectified_png", false), sdk::Param::real("max_range_mm", "50000"),
};

// The `runtime:` block, described as settings are (README "Runtime"); policy has no
// default: unset, the source decides.
const binocle_param_desc kRuntimeKeys[] = {
    sdk::Param::choice("policy", "lossless", "lossless|latest"),
    sdk::Param::integer("queue_depth", "4").min(1).max(1024),
    sdk::Param::integer("matcher_instances", "1").min(1).max(64),
    sdk::Param::choice("on_source_error", "stop", "stop|retry"),
    sdk::Param::real("retry_for_s", "30"), // > 0: checked after, in words of seconds
};

std::vector<std::string> namesOf(const binocle_param_desc *table, size_t count) {
    std::vector<std::string> names;
    for (size_t i = 0; i < count; ++i) names.emplace_back(table[i].name);
    return names;
}

RuntimeOptions runtimeBlock(const YAML::Node &r, const Context &ctx) {
    RuntimeOptions rt;
    if (!r.IsDefined() || r.IsNull()) return rt;
    if (!r.IsMap()) ctx.fail(r, "runtime", "expected a map (policy: lossless, queue_depth: 4, ...)");
    if (auto unknown = input::findUnknownKey(r, namesOf(kRuntimeKeys, std::size(kRuntimeKeys))))
        ctx.raise(ctx.at(unknown->key, "runtime." + unknown->name), "runtime: " + unknown->message);
    auto read = [&](const binocle_param_desc &d) -> std::optional<sdk::SettingValue> {
        YAML::Node n = r[d.name];
        if (!n) return std::nullopt; // a key given with no value is refused, as in a plugin block
        return readScalar(d, n, ctx, std::string("runtime.") + d.name);
    };
    if (auto p = read(kRuntimeKeys[0]))
        rt.policy = p->text == "latest" ? RuntimeOptions::Policy::Latest : RuntimeOptions::Policy::Lossless;
    if (auto v = read(kRuntimeKeys[1])) rt.queue_depth = static_cast<int>(v->integer);
    if (auto v = read(kRuntimeKeys[2])) rt.matcher_instances = static_cast<int>(v->integer);
    if (auto e = read(kRuntimeKeys[3]))
        rt.on_source_error = e->text == "retry" ? RuntimeOptions::OnSourceError::Retry : RuntimeOptions::OnSourceError::Stop;
    if (auto v = read(kRuntimeKeys[4])) {
        const YAML::Node n = r["retry_for_s"];
        if (!(v->real > 0))
            ctx.fail(n, "runtime.retry_for_s", "value '" + scalarText(n) + "' is not valid: expected a positive number of seconds");
        if (rt.on_source_error != RuntimeOptions::OnSourceError::Retry)
            ctx.fail(n, "runtime.retry_for_s", "is only used with on_source_error: retry (on_source_error is stop)");
        rt.retry_for_s = v->real;
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
    b.isolation = isolation;
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
    if (auto unknown = input::findUnknownKey(root, topKeys()))
        ctx.raise(ctx.at(unknown->key, unknown->name), unknown->message);
    RigConfig rig;
    rig.file = ctx.file;
    rig.base_dir = ctx.base_dir;
    if (YAML::Node n = root["name"]; n.IsDefined() && !n.IsNull()) {
        if (!n.IsScalar()) ctx.fail(n, "name", "value " + scalarText(n) + " is not valid: expected a text");
        rig.name = n.Scalar();
    } else {
        rig.name = fs::path(ctx.file).stem().string();
    }
    for (const PluginKind *k : pluginKinds()) {
        const YAML::Node node = root[k->rigKey];
        if (k->inRig == PluginKind::InRig::List)
            rig.plugins[k->kind] = blockList(node, k->rigKey, k->kind, host, ctx);
        else if (k->inRig == PluginKind::InRig::One || (node.IsDefined() && !node.IsNull()))
            rig.plugins[k->kind] = {block(node, k->rigKey, k->kind, host, ctx)};
    }
    if (YAML::Node c = root["calibration"]; c.IsDefined() && !c.IsNull()) {
        if (!c.IsScalar()) ctx.fail(c, "calibration", "expected the path of a calibration file (OpenCV FileStorage YAML)");
        fs::path p = c.Scalar();
        if (p.is_relative()) p = fs::path(ctx.base_dir) / p;
        if (!fs::exists(p)) ctx.fail(c, "calibration", "file '" + p.string() + "' does not exist");
        if (std::error_code ec; !fs::is_regular_file(p, ec))
            ctx.fail(c, "calibration", "'" + p.string() + "' is not a file (expected an OpenCV FileStorage YAML calibration)");
        rig.calibration_file = p.lexically_normal().string();
    }
    if (YAML::Node o = root["outputs"]; o.IsDefined() && !o.IsNull()) {
        if (!o.IsMap()) ctx.fail(o, "outputs", "expected a map (disparity_png: true, ...)");
        if (auto unknown = input::findUnknownKey(o, namesOf(kOutputKeys, std::size(kOutputKeys))))
            ctx.raise(ctx.at(unknown->key, "outputs." + unknown->name), "outputs: " + unknown->message);
        auto read = [&](const binocle_param_desc &d) -> std::optional<sdk::SettingValue> {
            YAML::Node n = o[d.name];
            if (!n) return std::nullopt;
            return readScalar(d, n, ctx, std::string("outputs.") + d.name);
        };
        bool *flags[] = {&rig.outputs.disparity_png, &rig.outputs.disparity_color, &rig.outputs.disparity_pfm,
                         &rig.outputs.cloud_ply, &rig.outputs.rectified_png};
        for (size_t i = 0; i < std::size(flags); ++i)
            if (auto v = read(kOutputKeys[i])) *flags[i] = v->boolean;
        if (auto v = read(kOutputKeys[5])) {
            if (!(v->real > 0))
                ctx.fail(o["max_range_mm"], "outputs.max_range_mm",
                         "value '" + scalarText(o["max_range_mm"]) + "' is not valid: expected a positive number of mm");
            rig.outputs.max_range_mm = v->real;
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

// How messages name an override: "--set key=value" for one from the command line, else
// its text, which says where it comes from ("test 3: source.range_mm=6000").
std::string labelOf(const Override &o) { return o.text == o.path + "=" + o.value ? "--set " + o.text : o.text; }

// A copy of `n` whose nodes carry no position: a value parsed from an override's text has
// marks that count from the start of that text, and a message about it would otherwise
// point at line 1 of the rig file, which never says it.
YAML::Node unmarked(const YAML::Node &n) {
    YAML::Node out;
    if (n.IsScalar()) {
        out = YAML::Node(n.Scalar());
    } else if (n.IsSequence()) {
        out = YAML::Node(YAML::NodeType::Sequence);
        for (const auto &e : n) out.push_back(unmarked(e));
    } else if (n.IsMap()) {
        out = YAML::Node(YAML::NodeType::Map);
        for (const auto &kv : n) out.force_insert(unmarked(kv.first), unmarked(kv.second));
    } else {
        out = YAML::Node(YAML::NodeType::Null);
    }
    out.SetTag(n.Tag());
    return out;
}

} // namespace

void applyOverride(YAML::Node &root, const Override &o) {
    const auto parts = splitPath(o.path);
    if (parts.empty()) throw OverrideError(labelOf(o) + ": empty key");
    YAML::Node value;
    try {
        value = unmarked(input::parseYaml(o.value, labelOf(o)));
    } catch (const input::YamlError &e) {
        throw OverrideError(e.what());
    }
    // A list index: decimal, within the list; checked before any conversion.
    auto index = [&](const YAML::Node &list, const std::string &part) -> size_t {
        int64_t i = 0;
        const int64_t last = static_cast<int64_t>(list.size()) - 1;
        if (!input::parseInteger(part, i, nullptr, 0, last))
            throw OverrideError(labelOf(o) + ": '" + sdk::printable(part) + "' is not an index of the list (" +
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
            throw OverrideError(labelOf(o) + ": '" + parts[i] + "' leads into a scalar value");
        }
        chain.push_back(next);
    }
    YAML::Node last = chain.back();
    if (last.IsSequence()) {
        last[index(last, parts.back())] = value;
    } else if (last.IsScalar()) {
        throw OverrideError(labelOf(o) + ": the parent of '" + parts.back() + "' is a scalar value");
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
