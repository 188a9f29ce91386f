// SPDX-License-Identifier: MIT
// A child process with a deadline: forked, runs a function that returns a text, and is
// killed when it runs past its time. Used to examine plugin files (isolation_examine.cpp)
// and to run conformance cases (framework/conformance), so that a crash or a hang in a
// plugin's code is a reason with the signal or the time, never the end of Binocle.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <sys/types.h>

namespace binocle {

// "signal 11 (SIGSEGV)".
std::string describeSignal(int sig);
// How a child ended, from waitpid's status: "killed by signal 11 (SIGSEGV)", "exited with status 3".
std::string describeExit(int status);
// Kills and reaps a child; returns its wait status.
int killAndReap(pid_t pid);

class DeadlineChild {
public:
    using Clock = std::chrono::steady_clock;
    // How the child ended.
    struct End {
        bool timedOut = false; // killed at its deadline
        int status = 0;        // waitpid's status
        std::string output;    // what the body returned (as far as it got written)
        double seconds = 0;
    };

    // Forks; the child runs `body`, writes what it returns to a pipe and exits with
    // status 0 (an exception that escapes `body` aborts it, as a crash). Throws Error
    // when the pipe or the fork fails.
    DeadlineChild(const std::function<std::string()> &body, int32_t timeout_ms);
    // Kills and reaps a child still running.
    ~DeadlineChild();
    DeadlineChild(const DeadlineChild &) = delete;
    DeadlineChild &operator=(const DeadlineChild &) = delete;

    // The pipe to poll for POLLIN.
    int fd() const { return pipe_; }
    // Milliseconds to the deadline (0 when past).
    int remainingMs() const;
    // Reads what the pipe holds; true once the child closed it (it ended).
    bool readSome();
    // Reaps a child whose pipe closed, or kills it when its deadline passed first.
    End finish();
    bool done() const { return pid_ < 0; }

    // Runs `body` in a child and waits for it, at most timeout_ms.
    static End run(const std::function<std::string()> &body, int32_t timeout_ms);

private:
    pid_t pid_ = -1;
    int pipe_ = -1;
    bool closed_ = false;
    std::string output_;
    Clock::time_point start_, deadline_;
};

} // namespace binocle
