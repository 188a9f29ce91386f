// SPDX-License-Identifier: MIT
// SIGINT / SIGTERM / SIGHUP for long runs: the first asks the run to stop cleanly (finish the
// frames in flight, write the summary), the second ends the process at once.
#pragma once

#include <atomic>

namespace binocle {

// While alive, SIGINT, SIGTERM and SIGHUP set `requested()` instead of killing the process; a
// second signal exits at once with 128 + signal. The previous handlers come back on
// destruction. One guard at a time per process.
class StopSignalGuard {
public:
    StopSignalGuard();
    ~StopSignalGuard();
    StopSignalGuard(const StopSignalGuard &) = delete;
    StopSignalGuard &operator=(const StopSignalGuard &) = delete;

    // The flag a run polls (RunOptions::stop).
    static const std::atomic<bool> &requested();
    // The signal that asked (0: none yet).
    static int signalNumber();
};

} // namespace binocle
