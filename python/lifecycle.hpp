// SPDX-License-Identifier: MIT
// The GIL, other Python threads, fork and the end of the interpreter: how the module
// waits without the GIL and takes it back, and how the work still open when Python exits
// (runs, experiments) is ended before the interpreter is torn down (docs/python.md,
// "Threads, fork and exit").
#pragma once

#include <pybind11/pybind11.h>

#include <chrono>
#include <memory>
#include <sys/types.h>
#include <unistd.h>

namespace binocle::python {

namespace py = pybind11;

// How often a call that waits without the GIL looks for Ctrl-C (PyErr_CheckSignals).
constexpr std::chrono::milliseconds kSignalPoll{50};

// Work that must end before the interpreter does: an open run, an experiment in progress.
class Ending {
public:
    Ending() : pid_(::getpid()) {}
    virtual ~Ending() = default;
    // Called by the exit hook, without the GIL: stops the work, waits for its end (the
    // summary written), and lets no new work start. Never throws.
    virtual void endAtExit() = 0;
    // True in a child forked after the work started: its threads are the parent's.
    bool forkedAway() const { return ::getpid() != pid_; }
    pid_t pid() const { return pid_; }

private:
    const pid_t pid_;
};

// Held (weakly) until the interpreter exits, then ended by the exit hook. Called with the
// GIL; throws binocle.Error once the interpreter has begun to exit (no new work then).
void keepUntilExit(const std::shared_ptr<Ending> &work);

namespace detail {
PyThreadState *releaseGil();
// Takes the GIL back, unless the interpreter has begun to exit: then this thread (a
// daemon thread Python is about to abandon) waits for ever, where Python would end it
// inside C++ code (pthread_exit through destructors: "terminate called").
void takeGilBack(PyThreadState *state) noexcept;
} // namespace detail

// Runs f without the GIL (other Python threads go on meanwhile) and takes it back.
template <class F>
auto withoutGil(F &&f) -> decltype(f()) {
    struct Back {
        PyThreadState *state;
        ~Back() { detail::takeGilBack(state); }
    } back{detail::releaseGil()};
    return f();
}

// At the module's import: numpy's C API imported once, under the GIL (a lazy import from
// several threads deadlocks), the exit hook registered (atexit), the fork handler set.
void setUpLifecycle();

} // namespace binocle::python
