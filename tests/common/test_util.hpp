// SPDX-License-Identifier: MIT
// Small helpers shared by tests: temporary folders, running the CLI, writing files.
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <sys/wait.h>

namespace binocle::test {

// A fresh folder under the system temp dir, removed when the object dies.
class TempDir {
public:
    TempDir() {
        std::random_device rd;
        path_ = std::filesystem::temp_directory_path() / ("binocle-test-" + std::to_string(rd()) + std::to_string(rd()));
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    const std::filesystem::path &path() const { return path_; }
    std::string str(const std::string &child = "") const { return child.empty() ? path_.string() : (path_ / child).string(); }

private:
    std::filesystem::path path_;
};

inline void writeText(const std::string &path, const std::string &text) {
    std::ofstream(path) << text;
}

struct CommandResult {
    int exit_code = -1;  // -1 when killed by a signal
    int signal = 0;
    std::string output;  // stdout and stderr together
};

// Runs a shell command line, capturing stdout and stderr.
inline CommandResult runCommand(const std::string &command) {
    CommandResult r;
    FILE *p = ::popen((command + " 2>&1").c_str(), "r");
    if (!p) return r;
    std::array<char, 4096> buf{};
    size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
    const int status = ::pclose(p);
    if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    return r;
}

// The built `binocle` with the build tree's plugins.
inline CommandResult runCli(const std::string &args, const std::string &pluginPath = BINOCLE_BUILD_PLUGIN_DIR) {
    return runCommand("BINOCLE_PLUGIN_PATH='" + pluginPath + "' '" + std::string(BINOCLE_CLI) + "' " + args);
}

} // namespace binocle::test
