// SPDX-License-Identifier: MIT
// SIGINT / SIGTERM / SIGHUP: a first signal asks for a clean stop, a second ends at once.
#include "pipeline/stop_signal.hpp"

#include "core/error.hpp"

#include <csignal>
#include <unistd.h>

namespace binocle {
namespace {

std::atomic<bool> g_requested{false};
std::atomic<int> g_signal{0};
std::atomic<bool> g_installed{false};
struct sigaction g_oldInt, g_oldTerm, g_oldHup;

void onStopSignal(int sig) {
    // Only async-signal-safe calls here: atomics and _exit.
    if (g_requested.exchange(true)) _exit(128 + sig);
    g_signal.store(sig);
}

} // namespace

StopSignalGuard::StopSignalGuard() {
    if (g_installed.exchange(true)) throw Error("internal: a second StopSignalGuard while one is alive");
    g_requested = false;
    g_signal = 0;
    struct sigaction sa {};
    sa.sa_handler = onStopSignal;
    sigemptyset(&sa.sa_mask);
    // Restart interrupted calls: a write in the middle of an output must not fail with EINTR.
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, &g_oldInt);
    sigaction(SIGTERM, &sa, &g_oldTerm);
    // A closed terminal (SSH dropped, tmux pane killed) is a request to stop like any
    // other: the frames in flight are finished and the summary written. Under nohup
    // (SIGHUP ignored) it stays ignored.
    sigaction(SIGHUP, nullptr, &g_oldHup);
    if (g_oldHup.sa_handler != SIG_IGN) sigaction(SIGHUP, &sa, nullptr);
}

StopSignalGuard::~StopSignalGuard() {
    sigaction(SIGINT, &g_oldInt, nullptr);
    sigaction(SIGTERM, &g_oldTerm, nullptr);
    sigaction(SIGHUP, &g_oldHup, nullptr);
    g_installed = false;
}

const std::atomic<bool> &StopSignalGuard::requested() { return g_requested; }
int StopSignalGuard::signalNumber() { return g_signal.load(); }

} // namespace binocle
