// SPDX-License-Identifier: MIT
// The plugin host: search path, loading with Boost.DLL, the checks of a table (read from
// its kind's descriptor) before any call.
#include "host/plugin_host.hpp"

#include "core/log.hpp"
#include "host/install_prefix.hpp"
#include "host/isolation.hpp"
#include "host/plugin_kinds.hpp"
#include "host/plugin_name.hpp"

#include <binocle/abi/init_error.h>
#include <binocle/text.hpp>

#include <algorithm>
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

namespace {

std::string join(const std::vector<std::string> &v, const char *sep = ", ") {
    std::string out;
    for (size_t i = 0; i < v.size(); ++i) out += (i ? sep : "") + v[i];
    return out;
}

} // namespace

std::vector<binocle_param_desc> PluginRecord::params() const {
    const PluginKind *k = table ? pluginKind(table->kind) : nullptr;
    return k ? k->params(table) : std::vector<binocle_param_desc>{};
}

bool validName(const char *name) {
    if (!name || !*name) return false;
    for (const char *c = name; *c; ++c)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= '0' && *c <= '9') || *c == '_')) return false;
    return true;
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
    // The build tree mirrors the install layout (bin/, lib/binocle/plugins/), so this
    // one entry serves both; nothing about the build tree is compiled in.
    if (const std::string prefix = installPrefix(); !prefix.empty())
        path.push_back((fs::path(prefix) / BINOCLE_PLUGIN_INSTALL_DIR).lexically_normal().string());
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
    if (!h) {
        std::string why;
        if (lib->has(BINOCLE_PLUGIN_INIT_ERROR_SYMBOL)) {
            const char *said = lib->get<const char *()>(BINOCLE_PLUGIN_INIT_ERROR_SYMBOL)();
            // The plugin's words, as text that cannot play tricks on a terminal.
            if (said && *said) why = ": " + sdk::printable(said, 500);
        }
        throw Error("init returned no table for host ABI " + std::to_string(BINOCLE_ABI_VERSION) + ", API " +
                    std::to_string(BINOCLE_API_VERSION) + why);
    }
    // The header layout is frozen: these fields are safe to read whatever the ABI.
    if (h->abi_version != BINOCLE_ABI_VERSION)
        throw Error("built for ABI version " + std::to_string(h->abi_version) + ", but this host speaks ABI version " +
                    std::to_string(BINOCLE_ABI_VERSION) + " (rebuild the plugin against this SDK)");
    if (h->struct_size < sizeof(binocle_plugin_header))
        throw Error("table size " + std::to_string(h->struct_size) + " is smaller than the plugin header (" +
                    std::to_string(sizeof(binocle_plugin_header)) + " bytes)");
    const PluginKind *kind = pluginKind(h->kind);
    if (!kind) throw Error("unknown plugin kind " + std::to_string(h->kind));
    if (h->api_version == 0) throw Error("API version 0 (the first API version is 1)");
    // Least size: API 1's for any plugin; the declared version's when the host knows it.
    size_t least = kind->leastTableSize(1);
    uint32_t leastApi = 1;
    for (uint32_t v = 2; v <= std::min<uint32_t>(h->api_version, BINOCLE_API_VERSION); ++v)
        if (size_t s = kind->leastTableSize(v)) least = s, leastApi = v;
    if (h->struct_size < least)
        throw Error("table size " + std::to_string(h->struct_size) + " is smaller than the " + kind->name +
                    " table of ABI " + std::to_string(BINOCLE_ABI_VERSION) + " API " + std::to_string(leastApi) + " (" +
                    std::to_string(least) + " bytes)");
    if (!validName(h->name))
        throw Error(std::string("invalid plugin name '") + (h->name ? h->name : "(null)") + "' (expected [a-z0-9_]+)");
    const std::string fileName = fs::path(path).filename().string();
    if (fileName != kPrefix + std::string(h->name) + ".so")
        throw Error(std::string("declares the name '") + h->name + "' but its file is " + fileName + " (the file of plugin <name> must be binocle_<name>.so)");

    // The host's copy: entries past struct_size read as absent (NULL), and entries a
    // newer plugin appended past the host's own table are not read.
    const size_t words = (kind->tableSize + sizeof(std::max_align_t) - 1) / sizeof(std::max_align_t);
    auto storage = std::make_shared<std::vector<std::max_align_t>>(words, std::max_align_t{});
    std::memcpy(static_cast<void *>(storage->data()), h, std::min<size_t>(h->struct_size, kind->tableSize));
    const auto *copy = reinterpret_cast<const binocle_plugin_header *>(storage->data());

    auto missing = kind->missingEntries(copy);
    if (!missing.empty()) throw Error(std::string("plugin '") + h->name + "' leaves mandatory entries NULL: " + join(missing));
    const auto [params, count] = kind->rawParams(copy);
    if (std::string why = settingsTableProblem(params, count); !why.empty())
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

} // namespace binocle
