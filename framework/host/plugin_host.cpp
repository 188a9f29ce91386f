// SPDX-License-Identifier: MIT
// The plugin host: search path, loading with Boost.DLL, ABI checks, instance wrappers.
#include "host/plugin_host.hpp"

#include "core/log.hpp"
#include "host/isolation.hpp"

#include <binocle/settings.hpp>

#include <algorithm>
#include <boost/dll/runtime_symbol_info.hpp>
#include <boost/dll/shared_library.hpp>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <spdlog/spdlog.h>
#include <sys/stat.h>

namespace fs = std::filesystem;

namespace binocle {

const char *kindName(int32_t kind) {
    switch (kind) {
    case BINOCLE_KIND_STEREO_SOURCE: return "source";
    case BINOCLE_KIND_MATCHER: return "matcher";
    case BINOCLE_KIND_CLOUD_TRANSFORM: return "transform";
    case BINOCLE_KIND_EVALUATOR: return "evaluator";
    default: return "unknown";
    }
}

const char *resultName(int32_t code) {
    switch (code) {
    case BINOCLE_OK: return "BINOCLE_OK";
    case BINOCLE_ERR_INVALID_ARGUMENT: return "BINOCLE_ERR_INVALID_ARGUMENT";
    case BINOCLE_ERR_NOT_FOUND: return "BINOCLE_ERR_NOT_FOUND";
    case BINOCLE_ERR_IO: return "BINOCLE_ERR_IO";
    case BINOCLE_ERR_DEVICE: return "BINOCLE_ERR_DEVICE";
    case BINOCLE_ERR_TIMEOUT: return "BINOCLE_ERR_TIMEOUT";
    case BINOCLE_ERR_END_OF_STREAM: return "BINOCLE_ERR_END_OF_STREAM";
    case BINOCLE_ERR_UNSUPPORTED: return "BINOCLE_ERR_UNSUPPORTED";
    case BINOCLE_ERR_BUSY: return "BINOCLE_ERR_BUSY";
    case BINOCLE_ERR_INTERNAL: return "BINOCLE_ERR_INTERNAL";
    default: return code >= BINOCLE_ERR_VENDOR_BASE ? "vendor error" : "unknown error";
    }
}

// ---- Records ------------------------------------------------------------------------

// End of a table entry: offsetof + sizeof. An entry's offset never changes once an API
// version has shipped (tables only grow at their end), so these values are frozen.
#define BINOCLE_END_OF(type, member) (offsetof(type, member) + sizeof(static_cast<type *>(nullptr)->member))

namespace {

struct TableVersion {
    int32_t kind;
    uint32_t api_version;
    size_t least;    // end of the last entry of that API version
    const char *last; // name of that entry, for messages
};

// One row per kind and API version. API 2 adds rows; it never edits these.
const TableVersion kTableVersions[] = {
    {BINOCLE_KIND_STEREO_SOURCE, 1, BINOCLE_END_OF(binocle_source_api, enumerate_devices), "enumerate_devices"},
    {BINOCLE_KIND_MATCHER, 1, BINOCLE_END_OF(binocle_matcher_api, disparity_range), "disparity_range"},
    {BINOCLE_KIND_CLOUD_TRANSFORM, 1, BINOCLE_END_OF(binocle_cloud_transform_api, apply), "apply"},
    {BINOCLE_KIND_EVALUATOR, 1, BINOCLE_END_OF(binocle_evaluator_api, finish), "finish"},
};

// Size of the kind's table as this host knows it (its own API version).
size_t hostTableSize(int32_t kind) {
    switch (kind) {
    case BINOCLE_KIND_STEREO_SOURCE: return sizeof(binocle_source_api);
    case BINOCLE_KIND_MATCHER: return sizeof(binocle_matcher_api);
    case BINOCLE_KIND_CLOUD_TRANSFORM: return sizeof(binocle_cloud_transform_api);
    case BINOCLE_KIND_EVALUATOR: return sizeof(binocle_evaluator_api);
    default: return 0;
    }
}

// Big enough for any kind's table: the host's normalised copy lives in one of these.
union AnyTable {
    binocle_plugin_header header;
    binocle_source_api source;
    binocle_matcher_api matcher;
    binocle_cloud_transform_api transform;
    binocle_evaluator_api evaluator;
};

} // namespace

size_t leastTableSize(int32_t kind, uint32_t api_version) {
    for (const auto &v : kTableVersions)
        if (v.kind == kind && v.api_version == api_version) return v.least;
    return 0;
}

namespace {

struct ParamTable {
    const binocle_param_desc *params;
    int32_t count;
};

ParamTable paramTable(const binocle_plugin_header *h) {
    switch (h->kind) {
    case BINOCLE_KIND_STEREO_SOURCE: {
        auto t = reinterpret_cast<const binocle_source_api *>(h);
        return {t->params, t->param_count};
    }
    case BINOCLE_KIND_MATCHER: {
        auto t = reinterpret_cast<const binocle_matcher_api *>(h);
        return {t->params, t->param_count};
    }
    case BINOCLE_KIND_CLOUD_TRANSFORM: {
        auto t = reinterpret_cast<const binocle_cloud_transform_api *>(h);
        return {t->params, t->param_count};
    }
    case BINOCLE_KIND_EVALUATOR: {
        auto t = reinterpret_cast<const binocle_evaluator_api *>(h);
        return {t->params, t->param_count};
    }
    default: return {nullptr, 0};
    }
}

// Names of the mandatory entries that are NULL.
std::vector<std::string> missingEntries(const binocle_plugin_header *h) {
    std::vector<std::string> missing;
    auto need = [&](const void *p, const char *name) {
        if (!p) missing.emplace_back(name);
    };
    switch (h->kind) {
    case BINOCLE_KIND_STEREO_SOURCE: {
        auto t = reinterpret_cast<const binocle_source_api *>(h);
        need(reinterpret_cast<const void *>(t->create), "create");
        need(reinterpret_cast<const void *>(t->destroy), "destroy");
        need(reinterpret_cast<const void *>(t->last_error), "last_error");
        need(reinterpret_cast<const void *>(t->grab), "grab");
        need(reinterpret_cast<const void *>(t->release_frame), "release_frame");
        break;
    }
    case BINOCLE_KIND_MATCHER: {
        auto t = reinterpret_cast<const binocle_matcher_api *>(h);
        need(reinterpret_cast<const void *>(t->create), "create");
        need(reinterpret_cast<const void *>(t->destroy), "destroy");
        need(reinterpret_cast<const void *>(t->last_error), "last_error");
        need(reinterpret_cast<const void *>(t->compute), "compute");
        break;
    }
    case BINOCLE_KIND_CLOUD_TRANSFORM: {
        auto t = reinterpret_cast<const binocle_cloud_transform_api *>(h);
        need(reinterpret_cast<const void *>(t->create), "create");
        need(reinterpret_cast<const void *>(t->destroy), "destroy");
        need(reinterpret_cast<const void *>(t->last_error), "last_error");
        need(reinterpret_cast<const void *>(t->apply), "apply");
        break;
    }
    case BINOCLE_KIND_EVALUATOR: {
        auto t = reinterpret_cast<const binocle_evaluator_api *>(h);
        need(reinterpret_cast<const void *>(t->create), "create");
        need(reinterpret_cast<const void *>(t->destroy), "destroy");
        need(reinterpret_cast<const void *>(t->last_error), "last_error");
        need(reinterpret_cast<const void *>(t->evaluate), "evaluate");
        break;
    }
    default: break;
    }
    return missing;
}

bool validName(const char *name) {
    if (!name || !*name) return false;
    for (const char *c = name; *c; ++c)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= '0' && *c <= '9') || *c == '_')) return false;
    return true;
}

std::string join(const std::vector<std::string> &v, const char *sep = ", ") {
    std::string out;
    for (size_t i = 0; i < v.size(); ++i) out += (i ? sep : "") + v[i];
    return out;
}

} // namespace

// ---- Settings tables --------------------------------------------------------------------

namespace {

// Why `text` is not a valid value of setting `d`, or "" when it is: the SDK's settings
// checker, the one the rig validation (config/) uses, applied to the plugin's own default.
std::string defaultProblem(const binocle_param_desc &d, const std::string &text) {
    sdk::SettingValue v;
    return sdk::readSetting(d, text, v).rule;
}

} // namespace

std::string settingsTableProblem(const binocle_param_desc *params, int32_t count) {
    if (count < 0 || count > 1000 || (count > 0 && !params))
        return "a garbage settings table (count " + std::to_string(count) + ")";
    std::map<std::string, int32_t> seen;
    for (int32_t i = 0; i < count; ++i) {
        const auto &d = params[i];
        const std::string at = "setting #" + std::to_string(i) + " '" + (d.name ? d.name : "(null)") + "'";
        if (!validName(d.name)) return at + ": invalid name (expected [a-z0-9_]+, e.g. window_px)";
        if (d.type < BINOCLE_PARAM_BOOL || d.type > BINOCLE_PARAM_DOUBLE_LIST)
            return at + ": unknown type " + std::to_string(d.type) + " (expected a BINOCLE_PARAM_* value)";
        if (auto [it, fresh] = seen.emplace(d.name, i); !fresh)
            return at + ": the name is declared twice (also setting #" + std::to_string(it->second) + ")";
        if ((d.flags & BINOCLE_PARAM_FLAG_HAS_MIN) && (d.flags & BINOCLE_PARAM_FLAG_HAS_MAX) && d.min > d.max)
            return at + ": min " + sdk::settingNumberText(d.min) + " is above max " + sdk::settingNumberText(d.max);
        if (d.type == BINOCLE_PARAM_ENUM && (!d.choices || !*d.choices)) return at + ": an enum without choices";
        if (d.flags & BINOCLE_PARAM_FLAG_REQUIRED) continue;
        if (!d.default_value) return at + ": no default, and not flagged BINOCLE_PARAM_FLAG_REQUIRED";
        if (std::string why = defaultProblem(d, d.default_value); !why.empty())
            return at + ": default '" + d.default_value + "' " + why;
    }
    return "";
}

std::vector<binocle_param_desc> PluginRecord::params() const {
    ParamTable t = paramTable(table);
    if (!t.params || t.count <= 0) return {};
    return {t.params, t.params + t.count};
}

// ---- Search and load ---------------------------------------------------------------------

namespace {

constexpr const char *kPrefix = "binocle_";

bool isPluginFileName(const std::string &name) {
    return name.size() > 11 && name.rfind(kPrefix, 0) == 0 && name.compare(name.size() - 3, 3, ".so") == 0;
}

// Why loading code from `path` is unsafe, or "": anyone but the owner (and root) could
// have put code there. Relative entries would depend on the working directory.
std::string unsafeReason(const std::string &path, bool folder) {
    if (fs::path(path).is_relative())
        return "relative search path entry (it would resolve against the working directory); use an absolute path";
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return "";
    if (st.st_mode & (S_IWGRP | S_IWOTH)) {
        std::ostringstream os;
        os << (folder ? "folder" : "file") << " is writable by others than its owner and root (mode " << std::oct
           << (st.st_mode & 07777) << "); run chmod go-w on it";
        return os.str();
    }
    return "";
}

} // namespace

std::vector<std::string> PluginHost::defaultSearchPath() {
    std::vector<std::string> path;
    if (const char *env = std::getenv("BINOCLE_PLUGIN_PATH")) {
        std::stringstream ss(env);
        std::string dir;
        while (std::getline(ss, dir, ':'))
            if (!dir.empty()) path.push_back(dir);
    }
    try {
        // The build tree mirrors the install layout (bin/, lib/binocle/plugins/), so this
        // one entry serves both; nothing about the build tree is compiled in.
        fs::path exe = boost::dll::program_location().string();
        path.push_back((exe.parent_path().parent_path() / BINOCLE_PLUGIN_INSTALL_DIR).lexically_normal().string());
    } catch (...) {
        // No program location (unusual); the other entries still apply.
    }
    std::vector<std::string> unique;
    for (const auto &d : path) {
        std::error_code ec;
        const std::string c = fs::weakly_canonical(d, ec).string();
        if (std::none_of(unique.begin(), unique.end(), [&](const std::string &u) { return fs::weakly_canonical(u, ec).string() == c; }))
            unique.push_back(d);
    }
    return unique;
}

PluginHost::PluginHost(std::vector<std::string> searchPath) : searchPath_(std::move(searchPath)) {}
PluginHost::~PluginHost() = default;

bool PluginHost::known(const std::string &canonical) const {
    return std::any_of(plugins_.begin(), plugins_.end(), [&](const PluginRecord &r) { return r.path == canonical; }) ||
           std::any_of(refused_.begin(), refused_.end(), [&](const Refusal &r) { return r.path == canonical; });
}

std::vector<std::string> PluginHost::safeFolders() const {
    std::vector<std::string> out;
    for (const auto &dir : searchPath_) {
        std::error_code ec;
        if (std::string why = unsafeReason(dir, true); !why.empty()) {
            if (!known(dir)) refused_.push_back({dir, why});
            continue;
        }
        if (fs::is_directory(dir, ec)) out.push_back(dir);
    }
    return out;
}

void PluginHost::scan(ScanMode mode, int32_t child_timeout_ms) const {
    std::vector<std::string> todo;
    std::vector<std::string> fileNames; // first folder wins for a file name
    for (const auto &dir : safeFolders()) {
        std::error_code ec;
        std::vector<fs::path> files;
        for (const auto &entry : fs::directory_iterator(dir, ec)) {
            const auto name = entry.path().filename().string();
            if (entry.is_regular_file(ec) && isPluginFileName(name)) files.push_back(entry.path());
        }
        std::sort(files.begin(), files.end());
        for (const auto &f : files) {
            const std::string canonical = fs::weakly_canonical(f, ec).string();
            const std::string name = f.filename().string();
            if (known(canonical) || std::find(fileNames.begin(), fileNames.end(), name) != fileNames.end()) continue;
            fileNames.push_back(name);
            todo.push_back(canonical);
        }
    }
    std::map<std::string, std::string> childRefusals;
    if (mode == ScanMode::Isolated) childRefusals = examineInChildren(todo, child_timeout_ms);
    for (const auto &path : todo) {
        if (auto it = childRefusals.find(path); it != childRefusals.end()) {
            refused_.push_back({path, it->second});
            continue;
        }
        try {
            inspect(path);
        } catch (const Error &e) {
            refused_.push_back({path, e.what()});
        }
    }
}

const PluginRecord &PluginHost::load(const std::string &path) {
    std::error_code ec;
    const std::string canonical = fs::weakly_canonical(path, ec).string();
    for (const auto &r : plugins_)
        if (r.path == canonical) return r;
    try {
        return inspect(canonical);
    } catch (const Error &e) {
        throw Error("plugin file " + canonical + " refused: " + e.what());
    }
}

std::string PluginHost::locate(const std::string &name) const {
    if (!validName(name.c_str())) return "";
    for (const auto &dir : safeFolders()) {
        std::error_code ec;
        const fs::path file = fs::path(dir) / (kPrefix + name + ".so");
        if (fs::exists(file, ec)) return fs::weakly_canonical(file, ec).string();
    }
    return "";
}

const PluginRecord *PluginHost::lookup(const std::string &name, int32_t kind) const {
    if (const PluginRecord *r = find(name)) return kind == 0 || r->kind == kind ? r : nullptr;
    const std::string path = locate(name);
    if (path.empty()) return nullptr;
    if (known(path)) return find(name, kind);
    try {
        const PluginRecord &r = inspect(path);
        return kind == 0 || r.kind == kind ? &r : nullptr;
    } catch (const Error &e) {
        refused_.push_back({path, e.what()});
        return nullptr;
    }
}

const PluginRecord *PluginHost::describe(const std::string &name, int32_t kind, int32_t timeout_ms) const {
    const std::string path = locate(name);
    if (path.empty()) return nullptr;
    for (const auto &r : described_)
        if (r.path == path) return kind == 0 || r.kind == kind ? &r : nullptr;
    for (const auto &r : refused_)
        if (r.path == path) return nullptr;
    try {
        if (std::string why = unsafeReason(path, false); !why.empty()) throw Error(why);
        PluginRecord r = describeInHelper(path, timeout_ms);
        described_.push_back(std::move(r));
        const PluginRecord &d = described_.back();
        return kind == 0 || d.kind == kind ? &d : nullptr;
    } catch (const Error &e) {
        refused_.push_back({path, e.what()});
        return nullptr;
    }
}

const PluginRecord &PluginHost::inspect(const std::string &path) const {
    if (std::string why = unsafeReason(path, false); !why.empty()) throw Error(why);
    auto lib = std::make_shared<boost::dll::shared_library>();
    try {
        // RTLD_NOW: a missing symbol is a refusal here, naming it, not a crash at the
        // first call. The library's constructors run now, before any check.
        lib->load(path, boost::dll::load_mode::rtld_now | boost::dll::load_mode::rtld_local);
    } catch (const std::exception &e) {
        // Boost wraps dlerror's text ("... (dlerror system message: <why>): <errno text>");
        // the dynamic loader's own words name the file and the missing symbol.
        std::string why = e.what();
        const std::string marker = "dlerror system message: ";
        if (auto at = why.find(marker); at != std::string::npos) {
            why = why.substr(at + marker.size());
            if (auto end = why.rfind("): "); end != std::string::npos) why = why.substr(0, end);
        }
        throw Error("cannot be loaded: " + why);
    }
    if (!lib->has(BINOCLE_PLUGIN_INIT_SYMBOL))
        throw Error(std::string("no init symbol '") + BINOCLE_PLUGIN_INIT_SYMBOL +
                    "' (not a Binocle plugin, or built without a BINOCLE_EXPORT_* macro)");
    auto init = lib->get<const binocle_plugin_header *(uint32_t, uint32_t)>(BINOCLE_PLUGIN_INIT_SYMBOL);
    const binocle_plugin_header *h = nullptr;
    try {
        h = init(BINOCLE_ABI_VERSION, BINOCLE_API_VERSION);
    } catch (...) {
        throw Error("init symbol threw an exception (exceptions must not cross the ABI)");
    }
    if (!h)
        throw Error("init returned no table for host ABI " + std::to_string(BINOCLE_ABI_VERSION) + ", API " +
                    std::to_string(BINOCLE_API_VERSION));
    // The header layout is frozen: these fields are safe to read whatever the ABI.
    if (h->abi_version != BINOCLE_ABI_VERSION)
        throw Error("built for ABI version " + std::to_string(h->abi_version) + ", but this host speaks ABI version " +
                    std::to_string(BINOCLE_ABI_VERSION) + " (rebuild the plugin against this SDK)");
    if (h->struct_size < sizeof(binocle_plugin_header))
        throw Error("table size " + std::to_string(h->struct_size) + " is smaller than the plugin header (" +
                    std::to_string(sizeof(binocle_plugin_header)) + " bytes)");
    const size_t hostSize = hostTableSize(h->kind);
    if (hostSize == 0) throw Error("unknown plugin kind " + std::to_string(h->kind));
    if (h->api_version == 0) throw Error("API version 0 (the first API version is 1)");
    // Least size: API 1's for any plugin; the declared version's when the host knows it.
    size_t least = leastTableSize(h->kind, 1);
    uint32_t leastApi = 1;
    for (uint32_t v = 2; v <= std::min<uint32_t>(h->api_version, BINOCLE_API_VERSION); ++v)
        if (size_t s = leastTableSize(h->kind, v)) least = s, leastApi = v;
    if (h->struct_size < least)
        throw Error("table size " + std::to_string(h->struct_size) + " is smaller than the " + kindName(h->kind) +
                    " table of ABI " + std::to_string(BINOCLE_ABI_VERSION) + " API " + std::to_string(leastApi) + " (" +
                    std::to_string(least) + " bytes)");
    if (!validName(h->name))
        throw Error(std::string("invalid plugin name '") + (h->name ? h->name : "(null)") + "' (expected [a-z0-9_]+)");
    const std::string fileName = fs::path(path).filename().string();
    if (fileName != kPrefix + std::string(h->name) + ".so")
        throw Error(std::string("declares the name '") + h->name + "' but its file is " + fileName + " (the file of plugin <name> must be binocle_<name>.so)");

    // The host's copy: entries past struct_size read as absent (NULL), and entries a
    // newer plugin appended past the host's own table are not read.
    auto storage = std::make_shared<AnyTable>();
    std::memset(static_cast<void *>(storage.get()), 0, sizeof(AnyTable));
    std::memcpy(static_cast<void *>(storage.get()), h, std::min<size_t>(h->struct_size, hostSize));
    const binocle_plugin_header *copy = &storage->header;

    auto missing = missingEntries(copy);
    if (!missing.empty()) throw Error(std::string("plugin '") + h->name + "' leaves mandatory entries NULL: " + join(missing));
    ParamTable pt = paramTable(copy);
    if (std::string why = settingsTableProblem(pt.params, pt.count); !why.empty())
        throw Error(std::string("plugin '") + h->name + "' declares " + why);
    if (const PluginRecord *other = find(h->name))
        throw Error(std::string("plugin name '") + h->name + "' is already provided by " + other->path);

    PluginRecord r;
    r.path = path;
    r.name = h->name;
    r.version = h->version ? h->version : "";
    r.description = h->description ? h->description : "";
    r.kind = h->kind;
    r.abi_version = h->abi_version;
    r.api_version = h->api_version;
    r.table = copy;
    r.tableStorage = storage;
    r.library = lib;
    plugins_.push_back(std::move(r));
    return plugins_.back();
}

const PluginRecord *PluginHost::find(const std::string &name, int32_t kind) const {
    for (const auto &r : plugins_)
        if (r.name == name && (kind == 0 || r.kind == kind)) return &r;
    return nullptr;
}

const PluginRecord &PluginHost::require(const std::string &name, int32_t kind) const {
    if (const PluginRecord *r = lookup(name, kind)) return *r;
    std::vector<std::string> names;
    for (const auto &r : plugins_)
        if (kind == 0 || r.kind == kind) names.push_back(r.name);
    std::string msg = std::string("no ") + (kind ? kindName(kind) : "") + " plugin named '" + name + "'";
    if (const PluginRecord *other = find(name)) msg += " (a " + std::string(kindName(other->kind)) + " plugin has that name)";
    msg += "; available: " + (names.empty() ? std::string("none") : join(names));
    for (const auto &ref : refused_)
        if (fs::path(ref.path).stem().string() == "binocle_" + name)
            msg += "; " + ref.path + " was refused: " + ref.reason;
    msg += " (search path: " + join(searchPath_, ":") + ")";
    throw Error(msg);
}

// ---- Settings -------------------------------------------------------------------------------

binocle_param &ParamValues::slot(const std::string &name) {
    for (auto &p : values_)
        if (name == p.name) return p;
    strings_.push_back(std::make_shared<std::string>(name));
    binocle_param p{};
    p.name = strings_.back()->c_str();
    values_.push_back(p);
    return values_.back();
}

void ParamValues::setBool(const std::string &name, bool v, bool isExplicit) {
    auto &p = slot(name);
    p.type = BINOCLE_PARAM_BOOL;
    p.i = v ? 1 : 0;
    p.explicit_ = isExplicit;
}

void ParamValues::setInt(const std::string &name, int64_t v, bool isExplicit) {
    auto &p = slot(name);
    p.type = BINOCLE_PARAM_INT;
    p.i = v;
    p.d = static_cast<double>(v);
    p.explicit_ = isExplicit;
}

void ParamValues::setDouble(const std::string &name, double v, bool isExplicit) {
    auto &p = slot(name);
    p.type = BINOCLE_PARAM_DOUBLE;
    p.d = v;
    p.explicit_ = isExplicit;
}

void ParamValues::setText(const std::string &name, int32_t type, const std::string &v, bool isExplicit) {
    auto &p = slot(name);
    strings_.push_back(std::make_shared<std::string>(v));
    p.type = type;
    p.s = strings_.back()->c_str();
    p.explicit_ = isExplicit;
}

const binocle_param *ParamValues::data() const { return values_.data(); }
int32_t ParamValues::size() const { return static_cast<int32_t>(values_.size()); }

const binocle_param *ParamValues::find(const std::string &name) const {
    for (const auto &p : values_)
        if (name == p.name) return &p;
    return nullptr;
}

// ---- Instances ---------------------------------------------------------------------------------

namespace {

struct SinkContext {
    std::string plugin;
    HostSink sink;
};

void hostLog(void *ctx, int32_t level, const char *message) {
    try {
        auto *c = static_cast<SinkContext *>(ctx);
        std::string msg = message ? message : "";
        if (c->sink.log) return c->sink.log(level, msg);
        logFromPlugin(c->plugin, level, msg);
    } catch (...) {
    }
}

void hostMetric(void *ctx, const char *name, double value, const char *unit) {
    try {
        auto *c = static_cast<SinkContext *>(ctx);
        if (c->sink.metric) c->sink.metric(name ? name : "", value, unit ? unit : "");
    } catch (...) {
    }
}

void hostText(void *ctx, const char *name, const char *text) {
    try {
        auto *c = static_cast<SinkContext *>(ctx);
        if (c->sink.text) c->sink.text(name ? name : "", text ? text : "");
    } catch (...) {
    }
}

// One SinkContext per binocle_host; owned through the binocle_host's context pointer.
struct HostBlock {
    binocle_host host;
    SinkContext ctx;
};

// binocle_host is the first member: deleting through it deletes the block.
void deleteHostBlock(binocle_host *h) { delete reinterpret_cast<HostBlock *>(h); }

} // namespace

PluginInstanceBase::PluginInstanceBase(const PluginRecord &record) : record_(record) {
    auto block = new HostBlock{};
    block->ctx.plugin = record.name;
    block->host.struct_size = sizeof(binocle_host);
    block->host.context = &block->ctx;
    block->host.log = &hostLog;
    block->host.report_metric = &hostMetric;
    block->host.report_text = &hostText;
    host_ = std::shared_ptr<binocle_host>(&block->host, deleteHostBlock);
}

void PluginInstanceBase::setSink(HostSink sink) { reinterpret_cast<HostBlock *>(host_.get())->ctx.sink = std::move(sink); }

int32_t PluginInstanceBase::restarts() const { return helper_ ? helper_->restarts() : 0; }
int64_t PluginInstanceBase::lostCalls() const { return helper_ ? helper_->lostCalls() : 0; }

bool PluginInstanceBase::runsIsolated(const PluginRecord &record, const ParamValues &params) {
    return params.isolation().process || record.described;
}

void PluginInstanceBase::fail(const std::string &what, int32_t code, const char *message) const {
    std::string msg = std::string(kindName(record_.kind)) + " plugin '" + record_.name + "' (" + record_.path + "): " + what +
                      " failed (" + resultName(code) + ")";
    if (message && *message) msg += ": " + std::string(message);
    throw PluginError(msg, code);
}

namespace {

// Checks an image a plugin handed back; returns "" when fine, else what is wrong.
std::string checkImage(const binocle_image &im, const char *what) {
    std::ostringstream os;
    const int bpp = bytesPerPixel(im.format);
    if (bpp == 0) os << what << " has unknown pixel format " << im.format;
    else if (im.width <= 0 || im.height <= 0 || im.width > 65536 || im.height > 65536)
        os << what << " has an impossible size " << im.width << "x" << im.height;
    else if (static_cast<int64_t>(im.stride_bytes) < static_cast<int64_t>(im.width) * bpp)
        os << what << " has stride " << im.stride_bytes << " bytes, less than width " << im.width << " x " << bpp << " bytes";
    else if (!im.data)
        os << what << " has no pixel data (NULL)";
    return os.str();
}

int cvType(int32_t format) {
    switch (format) {
    case BINOCLE_PIXEL_GRAY8: return CV_8UC1;
    case BINOCLE_PIXEL_GRAY16: return CV_16UC1;
    case BINOCLE_PIXEL_BGR8:
    case BINOCLE_PIXEL_RGB8: return CV_8UC3;
    case BINOCLE_PIXEL_FLOAT32: return CV_32FC1;
    default: return -1;
    }
}

cv::Mat view(const binocle_image &im) {
    return cv::Mat(im.height, im.width, cvType(im.format), im.data, static_cast<size_t>(im.stride_bytes));
}

binocle_image wrap(const cv::Mat &m, int32_t format) {
    binocle_image im{};
    im.width = m.cols;
    im.height = m.rows;
    im.stride_bytes = static_cast<int32_t>(m.step[0]);
    im.format = format;
    im.data = m.data;
    return im;
}

int32_t formatOf(const cv::Mat &m) {
    switch (m.type()) {
    case CV_8UC1: return BINOCLE_PIXEL_GRAY8;
    case CV_16UC1: return BINOCLE_PIXEL_GRAY16;
    case CV_8UC3: return BINOCLE_PIXEL_BGR8;
    case CV_32FC1: return BINOCLE_PIXEL_FLOAT32;
    default: throw Error("image type " + std::to_string(m.type()) + " cannot cross the plugin ABI");
    }
}

} // namespace

// ---- LentFrame ---------------------------------------------------------------------------------

LentFrame::LentFrame(std::shared_ptr<void> keep, const binocle_source_api *api, binocle_source *src,
                     const binocle_stereo_frame &f)
    : keep_(std::move(keep)), api_(api), src_(src), frame_(f) {}

LentFrame::LentFrame(std::shared_ptr<void> keep, const binocle_stereo_frame &f)
    : keep_(std::move(keep)), api_(nullptr), src_(nullptr), frame_(f) {}

LentFrame::~LentFrame() {
    if (!api_) return; // keep_ holds the copy; dropping it is the release
    try {
        const int32_t rc = api_->release_frame(src_, frame_.frame_id);
        if (rc != BINOCLE_OK) {
            const char *why = api_->last_error(src_);
            spdlog::error("source plugin '{}': release_frame of frame {} (sequence {}) failed ({}){}{}",
                          api_->header.name ? api_->header.name : "?", frame_.frame_id,
                          frame_.sequence, resultName(rc), why && *why ? ": " : "", why ? why : "");
        }
    } catch (...) {
    }
}

cv::Mat LentFrame::left() const { return view(frame_.left); }
cv::Mat LentFrame::right() const { return view(frame_.right); }

cv::Mat LentFrame::extra(const std::string &name) const {
    for (int32_t i = 0; i < frame_.extra_count; ++i)
        if (frame_.extras[i].name && name == frame_.extras[i].name) return view(frame_.extras[i].image);
    return {};
}

// ---- Source ------------------------------------------------------------------------------------

Source::Source(const PluginRecord &record, const ParamValues &params)
    : PluginInstanceBase(record), api_(reinterpret_cast<const binocle_source_api *>(record.table)) {
    if (runsIsolated(record, params)) {
        // create and every later call run in the helper process only.
        isolated_ = std::make_unique<SourceHelper>(record, params, host_.get());
        helper_ = isolated_.get();
        return;
    }
    binocle_source *h = nullptr;
    int32_t rc = api_->create(params.data(), params.size(), host_.get(), &h);
    if (rc != BINOCLE_OK || !h) fail("create", rc ? rc : BINOCLE_ERR_INTERNAL, api_->last_error(nullptr));
    // The handle outlives this object while frames are lent (each LentFrame holds it),
    // and keeps the library and the host block alive in turn.
    auto lib = record.library;
    auto api = api_;
    auto hostBlock = host_;
    handle_ = std::shared_ptr<binocle_source>(h, [api, lib, hostBlock](binocle_source *p) {
        try {
            api->destroy(p);
        } catch (...) {
        }
    });
}

Source::~Source() {
    if (handle_ && api_->stop) {
        try {
            api_->stop(handle_.get());
        } catch (...) {
        }
    }
}

void Source::start() {
    if (isolated_) return isolated_->start();
    if (!api_->start) return;
    int32_t rc = api_->start(handle_.get());
    if (rc != BINOCLE_OK) fail("start", rc, api_->last_error(handle_.get()));
}

void Source::stop() {
    if (isolated_) return isolated_->stop();
    if (!api_->stop) return;
    int32_t rc = api_->stop(handle_.get());
    if (rc != BINOCLE_OK) fail("stop", rc, api_->last_error(handle_.get()));
}

std::unique_ptr<LentFrame> Source::grab(int32_t timeout_ms) {
    if (isolated_) return isolated_->grab(timeout_ms);
    binocle_stereo_frame f{};
    f.struct_size = sizeof(f);
    int32_t rc = api_->grab(handle_.get(), timeout_ms, &f);
    if (rc == BINOCLE_ERR_END_OF_STREAM) return nullptr;
    if (rc != BINOCLE_OK) fail("grab", rc, api_->last_error(handle_.get()));
    // From here the frame is lent: any refusal below still gives it back.
    auto lent = std::make_unique<LentFrame>(handle_, api_, handle_.get(), f);
    std::string bad = checkImage(f.left, "left image");
    if (bad.empty()) bad = checkImage(f.right, "right image");
    if (bad.empty() && (f.left.width != f.right.width || f.left.height != f.right.height || f.left.format != f.right.format))
        bad = "left and right images differ: " + std::to_string(f.left.width) + "x" + std::to_string(f.left.height) +
              " format " + std::to_string(f.left.format) + " vs " + std::to_string(f.right.width) + "x" +
              std::to_string(f.right.height) + " format " + std::to_string(f.right.format);
    if (bad.empty() && (f.left.format == BINOCLE_PIXEL_FLOAT32 || f.left.format == BINOCLE_PIXEL_GRAY16))
        bad = "left/right images must be GRAY8, BGR8 or RGB8";
    if (bad.empty() && (f.extra_count < 0 || f.extra_count > 64 || (f.extra_count > 0 && !f.extras)))
        bad = "garbage extra plane count " + std::to_string(f.extra_count);
    for (int32_t i = 0; bad.empty() && i < f.extra_count; ++i) {
        std::string name = f.extras[i].name ? f.extras[i].name : "(unnamed)";
        bad = checkImage(f.extras[i].image, ("extra plane '" + name + "'").c_str());
    }
    if (!bad.empty()) fail("grab", BINOCLE_ERR_INTERNAL, ("returned an invalid frame: " + bad).c_str());
    return lent;
}

std::string Source::calibration() {
    if (isolated_) return isolated_->calibration();
    if (!api_->calibration) return {};
    const char *yaml = nullptr;
    int32_t rc = api_->calibration(handle_.get(), &yaml);
    if (rc != BINOCLE_OK) fail("calibration", rc, api_->last_error(handle_.get()));
    return yaml ? yaml : "";
}

std::string Source::statistics() {
    if (isolated_) return isolated_->statistics();
    if (!api_->statistics) return {};
    const char *yaml = nullptr;
    int32_t rc = api_->statistics(handle_.get(), &yaml);
    if (rc != BINOCLE_OK) fail("statistics", rc, api_->last_error(handle_.get()));
    return yaml ? yaml : "";
}

std::string Source::enumerateDevices(const PluginRecord &record) {
    auto api = reinterpret_cast<const binocle_source_api *>(record.table);
    if (!api->enumerate_devices) return "[]";
    HostBlock block{};
    block.ctx.plugin = record.name;
    block.host.struct_size = sizeof(binocle_host);
    block.host.context = &block.ctx;
    block.host.log = &hostLog;
    block.host.report_metric = &hostMetric;
    block.host.report_text = &hostText;
    const char *yaml = nullptr;
    int32_t rc = api->enumerate_devices(&block.host, &yaml);
    if (rc != BINOCLE_OK) {
        const char *m = api->last_error(nullptr);
        throw PluginError("source plugin '" + record.name + "' (" + record.path + "): enumerate_devices failed (" +
                              resultName(rc) + ")" + (m && *m ? ": " + std::string(m) : ""),
                          rc);
    }
    return yaml ? yaml : "[]";
}

// ---- Matcher -----------------------------------------------------------------------------------

Matcher::Matcher(const PluginRecord &record, const ParamValues &params)
    : PluginInstanceBase(record), api_(reinterpret_cast<const binocle_matcher_api *>(record.table)) {
    if (runsIsolated(record, params)) {
        // The plugin's create and every later call run in the helper process only.
        isolated_ = std::make_unique<MatcherHelper>(record, params, host_.get());
        helper_ = isolated_.get();
        return;
    }
    int32_t rc = api_->create(params.data(), params.size(), host_.get(), &handle_);
    if (rc != BINOCLE_OK || !handle_) fail("create", rc ? rc : BINOCLE_ERR_INTERNAL, api_->last_error(nullptr));
}

Matcher::~Matcher() {
    if (handle_) api_->destroy(handle_);
}

cv::Mat Matcher::compute(const cv::Mat &left, const cv::Mat &right) {
    cv::Mat disparity;
    compute(left, right, disparity);
    return disparity;
}

void Matcher::compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity) {
    if (left.size() != right.size() || left.type() != right.type())
        throw Error("matcher '" + record_.name + "': left and right images differ in size or type");
    disparity.create(left.size(), CV_32F);
    disparity.setTo(cv::Scalar(BINOCLE_INVALID_DISPARITY));
    if (isolated_) isolated_->compute(left, right, disparity);
    else computeInto(left, right, disparity);
    // A disparity is at most the image width; inf, NaN or 1e30 would become cloud points.
    const float limit = static_cast<float>(disparity.cols);
    uint64_t bad = 0;
    for (int y = 0; y < disparity.rows; ++y) {
        float *row = disparity.ptr<float>(y);
        for (int x = 0; x < disparity.cols; ++x)
            if (!std::isfinite(row[x]) || row[x] > limit) {
                row[x] = BINOCLE_INVALID_DISPARITY;
                ++bad;
            }
    }
    if (bad) {
        invalidated_ += bad;
        if (!warnedInvalid_)
            spdlog::warn("matcher plugin '{}': {} disparities not finite or beyond the image width ({} px) made invalid "
                         "(counted; further frames at debug level)", record_.name, bad, disparity.cols);
        else
            spdlog::debug("matcher plugin '{}': {} disparities not finite or absurd made invalid ({} so far)", record_.name,
                          bad, invalidated_);
        warnedInvalid_ = true;
    }
}

void Matcher::computeInto(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity) {
    binocle_image l = wrap(left, formatOf(left)), r = wrap(right, formatOf(right));
    binocle_image d = wrap(disparity, BINOCLE_PIXEL_FLOAT32);
    const binocle_image expected = d;
    int32_t rc = api_->compute(handle_, &l, &r, &d);
    if (rc != BINOCLE_OK) fail("compute", rc, api_->last_error(handle_));
    if (d.data != expected.data || d.width != expected.width || d.height != expected.height || d.format != expected.format ||
        d.stride_bytes != expected.stride_bytes)
        fail("compute", BINOCLE_ERR_INTERNAL, "changed the host's disparity image description instead of writing into it");
}

std::pair<int32_t, int32_t> Matcher::disparityRange() {
    if (isolated_) return isolated_->disparityRange();
    int32_t mn = 0, num = 0;
    if (!api_->disparity_range) return {0, 0};
    int32_t rc = api_->disparity_range(handle_, &mn, &num);
    if (rc != BINOCLE_OK) fail("disparity_range", rc, api_->last_error(handle_));
    return {mn, num};
}

// ---- CloudTransform ------------------------------------------------------------------------------

CloudTransform::CloudTransform(const PluginRecord &record, const ParamValues &params)
    : PluginInstanceBase(record), api_(reinterpret_cast<const binocle_cloud_transform_api *>(record.table)) {
    if (runsIsolated(record, params)) {
        isolated_ = std::make_unique<TransformHelper>(record, params, host_.get());
        helper_ = isolated_.get();
        return;
    }
    int32_t rc = api_->create(params.data(), params.size(), host_.get(), &handle_);
    if (rc != BINOCLE_OK || !handle_) fail("create", rc ? rc : BINOCLE_ERR_INTERNAL, api_->last_error(nullptr));
}

CloudTransform::~CloudTransform() {
    if (handle_) api_->destroy(handle_);
}

void CloudTransform::apply(binocle_cloud &cloud) {
    if (isolated_) return isolated_->apply(cloud); // the helper's wrapper checked the cloud
    const binocle_cloud before = cloud;
    int32_t rc = api_->apply(handle_, &cloud);
    if (rc != BINOCLE_OK) fail("apply", rc, api_->last_error(handle_));
    if (cloud.count < 0 || cloud.count > before.count || cloud.xyz != before.xyz || cloud.rgb != before.rgb ||
        cloud.pixel != before.pixel || (cloud.frame != BINOCLE_FRAME_CAMERA && cloud.frame != BINOCLE_FRAME_GROUND)) {
        const int64_t count = cloud.count;
        cloud = before;
        fail("apply", BINOCLE_ERR_INTERNAL,
             ("returned a garbage cloud (count " + std::to_string(count) + " of " + std::to_string(before.count) +
              ", arrays or frame changed)")
                 .c_str());
    }
}

// ---- Evaluator -----------------------------------------------------------------------------------

Evaluator::Evaluator(const PluginRecord &record, const ParamValues &params, HostSink sink)
    : PluginInstanceBase(record), api_(reinterpret_cast<const binocle_evaluator_api *>(record.table)) {
    setSink(std::move(sink));
    if (runsIsolated(record, params)) {
        isolated_ = std::make_unique<EvaluatorHelper>(record, params, host_.get());
        helper_ = isolated_.get();
        return;
    }
    int32_t rc = api_->create(params.data(), params.size(), host_.get(), &handle_);
    if (rc != BINOCLE_OK || !handle_) fail("create", rc ? rc : BINOCLE_ERR_INTERNAL, api_->last_error(nullptr));
}

Evaluator::~Evaluator() {
    if (handle_) api_->destroy(handle_);
}

void Evaluator::evaluate(const binocle_eval_input &input) {
    if (isolated_) return isolated_->evaluate(input);
    int32_t rc = api_->evaluate(handle_, &input);
    if (rc != BINOCLE_OK) fail("evaluate", rc, api_->last_error(handle_));
}

void Evaluator::finish() {
    if (isolated_) return isolated_->finish();
    if (!api_->finish) return;
    int32_t rc = api_->finish(handle_);
    if (rc != BINOCLE_OK) fail("finish", rc, api_->last_error(handle_));
}

} // namespace binocle
