// SPDX-License-Identifier: MIT
// Helpers of the host tests: a PluginHost over the fixture plugins (tests/fixtures), mock
// instances from YAML settings, and the `binocle` executable run as a child process.
#pragma once

#include "common/test_util.hpp"
#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"

#include <binocle/abi.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cerrno>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <memory>
#include <spawn.h>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <vector>
#include <yaml-cpp/yaml.h>

extern char **environ;

namespace binocle::test {

inline std::string fixturePath(const std::string &name) {
    return std::string(BINOCLE_TEST_PLUGIN_DIR) + "/binocle_" + name + ".so";
}

// Every fixture plugin, scanned once, as `binocle` would with BINOCLE_PLUGIN_PATH set to
// the fixture folder alone.
inline const PluginHost &fixtureHost() {
    static const std::unique_ptr<PluginHost> host = [] {
        auto h = std::make_unique<PluginHost>(std::vector<std::string>{BINOCLE_TEST_PLUGIN_DIR});
        h->scan();
        return h;
    }();
    return *host;
}

inline const PluginRecord &fixture(const std::string &name, int32_t kind) { return fixtureHost().require(name, kind); }

// Why the host refused binocle_<name>.so, or "" when it did not.
inline std::string refusalOf(const std::string &name) {
    for (const auto &r : fixtureHost().refused())
        if (std::filesystem::path(r.path).filename() == "binocle_" + name + ".so") return r.reason;
    return "";
}

template <class Instance>
Instance makeInstance(const std::string &name, int32_t kind, const std::string &yaml = "{}") {
    const PluginRecord &record = fixture(name, kind);
    return Instance(record, paramsFromYaml(record, yaml));
}

template <class Instance>
std::unique_ptr<Instance> newInstance(const std::string &name, int32_t kind, const std::string &yaml = "{}") {
    const PluginRecord &record = fixture(name, kind);
    return std::make_unique<Instance>(record, paramsFromYaml(record, yaml));
}

// One counter of a source's statistics() YAML ("released: 3").
inline int64_t statistic(Source &source, const std::string &key) {
    YAML::Node n = YAML::Load(source.statistics());
    if (!n[key]) throw std::runtime_error("statistics have no key '" + key + "': " + source.statistics());
    return n[key].as<int64_t>();
}

// The message of the PluginError `f` throws; fails the test when it throws none or another type.
template <class F>
std::string pluginErrorOf(F &&f) {
    try {
        f();
    } catch (const PluginError &e) {
        return e.what();
    } catch (const std::exception &e) {
        ADD_FAILURE() << "expected binocle::PluginError, got another exception: " << e.what();
        return e.what();
    }
    ADD_FAILURE() << "expected binocle::PluginError, nothing was thrown";
    return "";
}

inline std::string readAll(const std::string &path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

struct ProcessResult {
    bool exited = false; // false: killed by a signal
    int exit_code = -1;
    int signal = 0;
    std::string out, err;
};

// Runs the built `binocle` with `args` and BINOCLE_PLUGIN_PATH = pluginPath, no shell in
// between, so that a crash shows as a signal and not as a shell's exit code.
inline ProcessResult runBinocle(const std::vector<std::string> &args, const std::string &pluginPath) {
    TempDir dir;
    const std::string out = dir.str("stdout"), err = dir.str("stderr");
    std::vector<std::string> argStrings{BINOCLE_CLI};
    argStrings.insert(argStrings.end(), args.begin(), args.end());
    std::vector<char *> argv;
    for (auto &a : argStrings) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<std::string> envStrings{"BINOCLE_PLUGIN_PATH=" + pluginPath};
    for (char **e = environ; *e; ++e)
        if (std::string(*e).rfind("BINOCLE_PLUGIN_PATH=", 0) != 0) envStrings.emplace_back(*e);
    std::vector<char *> envp;
    for (auto &e : envStrings) envp.push_back(e.data());
    envp.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    ProcessResult r;
    if (rc != 0) {
        r.err = "posix_spawn of " + argStrings[0] + " failed: " + std::to_string(rc);
        return r;
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    r.exited = WIFEXITED(status);
    r.exit_code = r.exited ? WEXITSTATUS(status) : -1;
    r.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    r.out = readAll(out);
    r.err = readAll(err);
    return r;
}

} // namespace binocle::test
