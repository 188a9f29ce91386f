// SPDX-License-Identifier: MIT
// The conformance kit: finds and loads the file (in a child first), checks its table and
// settings, then runs its kind's family of cases (cases_<kind>.cpp), each in a child
// process of its own; and the JUnit report.
#include "conformance/conformance.hpp"

#include "config/rig_config.hpp"
#include "conformance/kit.hpp"
#include "core/error.hpp"
#include "host/isolation.hpp"
#include "host/plugin_host.hpp"
#include "host/plugin_kinds.hpp"
#include "input/utf8.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <sstream>

namespace fs = std::filesystem;

namespace binocle {

// The families of cases, one per kind (cases_<kind>.cpp defines <kind>Cases); the list is
// generated from those file names (framework/CMakeLists.txt), so a new kind edits no list.
namespace conformance {
std::vector<std::pair<const char *, void (*)(Battery &)>> familiesByFile();
} // namespace conformance

int ConformanceReport::count(ConformanceCase::Status s) const {
    return static_cast<int>(std::count_if(cases.begin(), cases.end(), [&](const ConformanceCase &c) { return c.status == s; }));
}

std::string ConformanceReport::summary() const {
    using S = ConformanceCase::Status;
    std::string line = std::to_string(count(S::Passed)) + " passed, " + std::to_string(count(S::Failed)) + " failed, " +
                       std::to_string(count(S::Skipped)) + " skipped";
    if (!complete())
        line += " (" + std::to_string(count(S::Skipped)) + " of " + std::to_string(cases.size()) +
                " cases did not run and checked nothing: not a full pass; see SKIP for why)";
    return line;
}

namespace {

using conformance::Status;
using Clock = std::chrono::steady_clock;

// Each kind's family of cases; a kind without one gets the load, table and settings cases.
using Family = void (*)(conformance::Battery &);
const std::map<int32_t, Family> &families() {
    static const std::map<int32_t, Family> f = [] {
        std::map<int32_t, Family> byKind;
        for (const auto &[name, family] : conformance::familiesByFile()) {
            const PluginKind *k = pluginKindNamed(name);
            if (!k) throw Error(std::string("conformance: cases_") + name + ".cpp names no plugin kind of the host");
            byKind[k->kind] = family;
        }
        return byKind;
    }();
    return f;
}

// The plugin's file: FILE.so as given, or binocle_NAME.so in the search path.
std::string pluginFile(const ConformanceOptions &options) {
    PluginHost finder(options.searchPath.empty() ? PluginHost::defaultSearchPath() : options.searchPath);
    std::string path = options.plugin;
    const bool isFile = path.find('/') != std::string::npos || (path.size() > 3 && path.compare(path.size() - 3, 3, ".so") == 0);
    if (!isFile) {
        path = finder.locate(options.plugin);
        if (path.empty()) {
            std::string why = "no file binocle_" + options.plugin + ".so in the search path (";
            for (size_t i = 0; i < finder.searchPath().size(); ++i) why += (i ? ":" : "") + finder.searchPath()[i];
            why += ")";
            for (const auto &r : finder.refused()) why += "; " + r.path + " refused: " + r.reason;
            throw Error(why);
        }
        return path;
    }
    std::error_code ec;
    if (!fs::exists(path, ec)) throw Error("plugin file " + path + " does not exist");
    return fs::weakly_canonical(path, ec).string();
}

// 1. The file, opened in a child first: its code runs at load. Then in this process.
const PluginRecord *loadCase(const std::string &path, int32_t timeout_ms, PluginHost &host, ConformanceReport &report) {
    ConformanceCase load{"load", Status::Passed, "", 0};
    const auto t0 = Clock::now();
    const auto refusals = examineInChildren({path}, std::min(timeout_ms, 5000));
    const PluginRecord *record = nullptr;
    if (auto it = refusals.find(path); it != refusals.end()) {
        load.status = Status::Failed;
        load.message = it->second;
    } else {
        try {
            record = &host.load(path);
            load.message = "opened with RTLD_NOW; ABI " + std::to_string(record->abi_version) + ", API " +
                           std::to_string(record->api_version);
        } catch (const std::exception &e) {
            load.status = Status::Failed;
            load.message = e.what();
        }
    }
    load.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    report.cases.push_back(load);
    return record;
}

// 2. The table and its settings (what load checks, said in full).
void tableCases(const PluginRecord &record, ConformanceReport &report) {
    ConformanceCase table{"table", Status::Passed, "", 0};
    std::ostringstream facts;
    facts << report.kind << " '" << record.name << "' " << record.version << ", table " << record.table->struct_size
          << " bytes (API 1 needs " << requireKind(record.kind).leastTableSize(1) << ")";
    table.message = facts.str();
    if (record.version.empty() || record.description.empty()) {
        table.status = Status::Failed;
        table.message = "the header's version or description is empty (binocle plugins shows them)";
    }
    report.cases.push_back(table);
    ConformanceCase settings{"settings", Status::Passed, "", 0};
    const auto descs = record.params();
    std::vector<std::string> noHelp;
    for (const auto &d : descs)
        if (!d.help || !*d.help) noHelp.emplace_back(d.name);
    if (!noHelp.empty()) {
        settings.status = Status::Failed;
        settings.message = "settings without help text (plugins --verbose shows it):";
        for (const auto &n : noHelp) settings.message += " " + n;
    } else {
        settings.message = std::to_string(descs.size()) + " settings: unique names, valid defaults, help text";
    }
    report.cases.push_back(settings);
}

// The settings for create: defaults, with --set on top. A --set the plugin refuses (an
// unknown key, a bad value) throws SettingsRefused; settings the plugin needs and nobody
// gave (a camera's address) leave `missing` saying so, and the instance cases are skipped.
ParamValues createSettings(const PluginRecord &record, const std::vector<std::string> &sets, std::string &missing) {
    std::error_code ec;
    const std::string base = fs::current_path(ec).string();
    const std::string where = "(plugin-check --set)";
    YAML::Node block(YAML::NodeType::Map);
    for (const auto &s : sets) {
        try {
            applyOverride(block, Override::parse(s));
        } catch (const Error &e) {
            throw SettingsRefused("--set " + s + ": " + e.what());
        }
    }
    std::string withoutSets;
    try {
        resolveParams(record, YAML::Node(YAML::NodeType::Map), record.name, where, base);
    } catch (const Error &e) {
        withoutSets = e.what();
    }
    try {
        return resolveParams(record, block, record.name, where, base);
    } catch (const Error &e) {
        // A refusal that names a key given with --set is that --set's fault; otherwise
        // (the same refusal as without any --set, a required key nobody gave) settings
        // are missing, not wrong.
        const std::string why = e.what();
        for (const auto &s : sets) {
            const std::string key = s.substr(0, s.find_first_of("=."));
            if (why != withoutSets && !key.empty() && why.find(key) != std::string::npos)
                throw SettingsRefused("--set " + s + " refused: " + why);
        }
        missing = why;
        return {};
    }
}

} // namespace

ConformanceReport checkPlugin(const ConformanceOptions &options) {
    ConformanceReport report;
    report.path = pluginFile(options);
    report.plugin = fs::path(report.path).stem().string();
    PluginHost host(std::vector<std::string>{});
    const PluginRecord *record = loadCase(report.path, options.case_timeout_ms, host, report);
    if (!record) return report;
    report.plugin = record->name;
    report.kind = kindName(record->kind);
    tableCases(*record, report);

    std::string missing;
    const ParamValues params = createSettings(*record, options.settings, missing);
    std::vector<ConformanceCase> cases;
    conformance::Battery battery{*record, params, options.case_timeout_ms, cases, ""};
    if (!missing.empty()) battery.skipAll = "cannot create an instance: " + missing + " (give settings with --set KEY=VALUE)";
    if (auto it = families().find(record->kind); it != families().end()) it->second(battery);
    report.cases.insert(report.cases.end(), cases.begin(), cases.end());
    return report;
}

std::string junitXml(const ConformanceReport &r) {
    std::ostringstream os;
    double total = 0;
    for (const auto &c : r.cases) total += c.seconds;
    const std::string classname = "plugin_check." + (r.kind.empty() ? std::string("unknown") : r.kind) + "." + r.plugin;
    os << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    os << "<testsuites tests=\"" << r.cases.size() << "\" failures=\"" << r.count(Status::Failed) << "\" skipped=\""
       << r.count(Status::Skipped) << "\">\n";
    os << "  <testsuite name=\"" << input::xmlEscape(classname) << "\" tests=\"" << r.cases.size() << "\" failures=\""
       << r.count(Status::Failed) << "\" errors=\"0\" skipped=\"" << r.count(Status::Skipped) << "\" time=\"" << total << "\">\n";
    os << "    <properties><property name=\"file\" value=\"" << input::xmlEscape(r.path) << "\"/></properties>\n";
    for (const auto &c : r.cases) {
        os << "    <testcase classname=\"" << input::xmlEscape(classname) << "\" name=\"" << input::xmlEscape(c.name) << "\" time=\"" << c.seconds << "\"";
        if (c.status == Status::Passed) {
            os << ">";
            if (!c.message.empty()) os << "<system-out>" << input::xmlEscape(c.message) << "</system-out>";
            os << "</testcase>\n";
        } else if (c.status == Status::Failed) {
            os << "><failure message=\"" << input::xmlEscape(c.message) << "\"/></testcase>\n";
        } else {
            os << "><skipped message=\"" << input::xmlEscape(c.message) << "\"/></testcase>\n";
        }
    }
    os << "  </testsuite>\n</testsuites>\n";
    return os.str();
}

} // namespace binocle
