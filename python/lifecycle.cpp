// SPDX-License-Identifier: MIT
// The GIL's gate, the exit hook and the fork handler (lifecycle.hpp).
#include "python/lifecycle.hpp"

#include "core/error.hpp"

#include <pybind11/numpy.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <pthread.h>
#include <vector>

namespace binocle::python {

namespace {

// Held while a thread decides to take the GIL back, and by the exit hook while it says
// that the interpreter is exiting: a thread either has the GIL back before the hook ends
// the open work, or sees that it must not take it. Order: the gate, then the GIL. A
// pointer: a child forked while another thread held it gets a fresh one.
std::mutex *g_gate = new std::mutex;
std::atomic<bool> g_exiting{false};
// The thread that runs the exit hook and then finalizes the interpreter (the main
// thread); it alone still takes the GIL back once the interpreter exits.
std::atomic<unsigned long> g_exitThread{0};

// The work that must end before the interpreter does; read and written with the GIL.
std::vector<std::weak_ptr<Ending>> &openWork() {
    static auto *work = new std::vector<std::weak_ptr<Ending>>; // never destroyed: used at exit
    return *work;
}

bool pythonFinalizing() {
#if PY_VERSION_HEX >= 0x030D0000
    return Py_IsFinalizing();
#else
    return _Py_IsFinalizing();
#endif
}

[[noreturn]] void waitForEver() {
    for (;;) ::pause();
}

// atexit: once the threads Python waits for have ended, before anything is torn down.
// Runs with the GIL, on the thread that then finalizes the interpreter.
void endOpenWork() {
    {
        PyThreadState *state = PyEval_SaveThread();
        {
            std::lock_guard<std::mutex> lock(*g_gate);
            g_exitThread = PyThread_get_thread_ident();
            g_exiting = true;
        }
        PyEval_RestoreThread(state);
    }
    // Every run or experiment registered from now on is refused (keepUntilExit), so this
    // list is all there is.
    std::vector<std::shared_ptr<Ending>> work;
    for (const auto &w : openWork())
        if (auto s = w.lock(); s && !s->forkedAway()) work.push_back(std::move(s));
    openWork().clear();
    withoutGil([&] {
        for (const auto &w : work) w->endAtExit();
    });
}

} // namespace

void keepUntilExit(const std::shared_ptr<Ending> &work) {
    if (g_exiting) throw Error("Python is exiting: no run or experiment starts now");
    auto &open = openWork();
    open.erase(std::remove_if(open.begin(), open.end(), [](const auto &w) { return w.expired(); }), open.end());
    open.push_back(work);
}

namespace detail {

PyThreadState *releaseGil() { return PyEval_SaveThread(); }

void takeGilBack(PyThreadState *state) noexcept {
    std::unique_lock<std::mutex> lock(*g_gate);
    if ((g_exiting || pythonFinalizing()) && PyThread_get_thread_ident() != g_exitThread) {
        // Python would end this thread in PyEval_RestoreThread (pthread_exit, unwinding
        // C++ frames that must not be unwound); its process is about to end anyway.
        lock.unlock();
        waitForEver();
    }
    PyEval_RestoreThread(state);
}

} // namespace detail

void setUpLifecycle() {
    // numpy's C API, imported here once: pybind11 imports it at the first array, under a
    // static guard that a second thread waits on while it holds the GIL, which the first
    // needs to finish numpy's import (four threads starting runs at once deadlocked).
    py::module_::import("numpy");
    (void)py::dtype::of<uint8_t>();
    g_exitThread = py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
    py::module_::import("atexit").attr("register")(py::cpp_function(&endOpenWork));
    // A child forked while a thread held the gate would wait on it for ever; its main
    // thread is the one that forked.
    static const int forkHandler = ::pthread_atfork(nullptr, nullptr, [] {
        g_gate = new std::mutex;
        g_exitThread = PyThread_get_thread_ident();
    });
    (void)forkHandler;
}

} // namespace binocle::python
