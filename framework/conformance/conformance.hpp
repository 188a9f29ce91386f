// SPDX-License-Identifier: MIT
// `binocle plugin-check`: the same battery of checks against any plugin of a kind, in
// the spirit of libcamera's lc-compliance, with a JUnit XML report for an author's CI.
#pragma once

#include "core/error.hpp"

#include <string>
#include <vector>

namespace binocle {

struct ConformanceOptions {
    std::string plugin;                 // FILE.so, or a NAME looked up as binocle_<NAME>.so
    std::vector<std::string> settings;  // "key=value" (YAML values) given to create
    std::vector<std::string> searchPath; // empty: PluginHost::defaultSearchPath()
    int32_t case_timeout_ms = 20000;     // one case longer than this fails
};

struct ConformanceCase {
    enum class Status { Passed, Failed, Skipped };
    std::string name;
    Status status = Status::Passed;
    std::string message; // why it failed or was skipped, or what was seen
    double seconds = 0;
};

struct ConformanceReport {
    std::string plugin; // name (or the file name when it could not be read)
    std::string path;
    std::string kind;   // "matcher" ... or "" when the table could not be read
    std::vector<ConformanceCase> cases;
    int count(ConformanceCase::Status s) const;
    bool passed() const { return count(ConformanceCase::Status::Failed) == 0; }
    // True when every case ran: a skipped case checked nothing, so a report with skips
    // is never read as a full pass.
    bool complete() const { return count(ConformanceCase::Status::Skipped) == 0; }
    // "3 passed, 0 failed, 6 skipped (not checked: ...)"; the line the CLI prints.
    std::string summary() const;
};

// A --set the plugin refuses (unknown key, bad value): the command line is wrong, and
// no case runs with settings the user did not mean.
class SettingsRefused : public Error {
public:
    using Error::Error;
};

// Runs every check that applies to the plugin's kind. Throws SettingsRefused for a --set
// the plugin refuses, Error when the file cannot be found. Each case that calls the plugin
// runs in a child process, so that a crash or a hang is a failed case (with the signal
// or the timeout), and the battery goes on.
ConformanceReport checkPlugin(const ConformanceOptions &options);

// The report as JUnit XML (one testsuite, one testcase per check).
std::string junitXml(const ConformanceReport &report);

} // namespace binocle
