// SPDX-License-Identifier: MIT
// Starts the built `binocle` as a child process with its output in a log file, for tests
// that signal it or race it; SIGHUP as a terminal leaves it, even under nohup.
#pragma once

#include <cstdlib>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <string>
#include <vector>

extern char **environ;

namespace binocle::test {

// `binocle ARGS...` with the build tree's plugins, stdout and stderr into `log`. Returns
// the child's pid, or -1.
inline pid_t spawnCli(const std::vector<std::string> &args, const std::string &log) {
    std::vector<std::string> all{BINOCLE_CLI};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char *> argv;
    for (auto &a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGHUP);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF);
    setenv("BINOCLE_PLUGIN_PATH", BINOCLE_BUILD_PLUGIN_DIR, 1);
    pid_t pid = -1;
    if (posix_spawn(&pid, argv[0], &actions, &attr, argv.data(), environ) != 0) pid = -1;
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    return pid;
}

} // namespace binocle::test
