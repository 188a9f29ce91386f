// SPDX-License-Identifier: MIT
// What every request of the application layer carries: who asks (the command line or
// Python) and how that caller's user spells an argument, and the error of a bad request.
#pragma once

#include "core/error.hpp"
#include "core/output_folder.hpp"
#include "pipeline/stop_signal.hpp"

#include <atomic>
#include <optional>
#include <string>

namespace binocle::app {

// A mistake in a request (a value the user gave the command line or the Python call):
// exit status 2 of `binocle`, binocle.UsageError in Python.
class RequestError : public Error {
public:
    using Error::Error;
};

// Who asks: "binocle run", "binocle design" ... on the command line, "binocle.Rig.run",
// "binocle.design" ... from Python (written in an output folder's lock, named in its
// refusals). Messages name the caller's own arguments: `--simulate-count` on the command
// line, `simulate_count` in Python.
struct Caller {
    std::string command = "binocle";

    bool python() const { return command.rfind("binocle.", 0) == 0; }
    // `name` in Python's spelling ("simulate_count"): "--simulate-count", or "simulate_count".
    std::string arg(const std::string &name) const;
    // An argument with the value the user gave: "--range 6000,", or "range='6000,'".
    std::string shown(const std::string &name, const std::string &value) const;
    // The claim of an output folder of `kind` by this caller: its command in the lock and
    // the marker, its spelling of force ("--force", "force=True") in a refusal.
    OutputClaim claim(OutputKind kind, bool force) const;
};

// The flag a job polls to stop cleanly: the caller's, or, when the caller gives none,
// SIGINT, SIGTERM and SIGHUP's while this lives (StopSignalGuard: a second signal ends
// the process).
class StopFlag {
public:
    explicit StopFlag(const std::atomic<bool> *stop);
    const std::atomic<bool> *flag() const { return stop_; }
    // The signal that asked (0: none yet, or the caller's flag).
    int signal() const { return signals_ ? StopSignalGuard::signalNumber() : 0; }

private:
    std::optional<StopSignalGuard> signals_;
    const std::atomic<bool> *stop_;
};

} // namespace binocle::app
