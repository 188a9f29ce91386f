// SPDX-License-Identifier: MIT
// binocle.experiment() (experiment_call.hpp): the arguments checked, the tests on a
// thread of their own, the experiment ended with the interpreter.
#include "python/experiment_call.hpp"

#include "python/arguments.hpp"
#include "python/convert.hpp"
#include "python/lifecycle.hpp"

#include "app/experiment_run.hpp"
#include "files/atomic_file.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

namespace fs = std::filesystem;

namespace binocle::python {

namespace {

// An experiment in progress, its tests on a thread of their own: asked to start no
// further test (Ctrl-C, the interpreter's exit), waited for and joined by the call or,
// when the interpreter exits first, by the exit hook.
class ExperimentWork final : public Ending {
public:
    std::atomic<bool> stop{false};
    std::optional<app::ExperimentRun> run; // its folder claimed before the tests start
    // Starts the tests; false (nothing started) once the interpreter exits.
    bool start(std::function<void()> tests) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (exiting_) return false;
        worker_ = std::thread([this, tests = std::move(tests)] {
            tests();
            std::lock_guard<std::mutex> done(mutex_);
            done_ = true;
            ended_.notify_all();
        });
        return true;
    }
    bool waitFor(std::chrono::milliseconds wait) {
        std::unique_lock<std::mutex> lock(mutex_);
        return ended_.wait_for(lock, wait, [&] { return done_; });
    }
    // Waits for the tests' thread, then lets go of the output folder (its lock) and the plugins.
    void join() {
        std::lock_guard<std::mutex> lock(joining_);
        if (worker_.joinable()) worker_.join();
        if (run) run->release();
    }
    // The test in progress ends, no other starts; the tables say "interrupted".
    void endAtExit() override {
        stop = true;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            exiting_ = true;
        }
        join();
    }

private:
    std::mutex mutex_, joining_;
    std::condition_variable ended_;
    std::thread worker_;
    bool done_ = false, exiting_ = false;
};

} // namespace

py::dict experiment(const py::object &file, const py::object &set, const py::object &out, const py::object &tests,
                    const py::object &force, const py::object &progress) {
    app::ExperimentRequest request;
    request.caller.command = "binocle.experiment";
    request.file = *pathText(file, "file");
    request.set = setTexts(set);
    request.out = pathText(out, "out", "out/<the experiment's name>").value_or("");
    request.tests = textList(tests, "tests");
    request.force = flag(force, "force");
    request.progress = flag(progress, "progress");
    auto work = std::make_shared<ExperimentWork>();
    keepUntilExit(work);
    request.stop = &work->stop;
    // Everything is checked before the first test runs (as `binocle experiment`).
    withoutGil([&] { work->run.emplace(request); });
    // The tests run on a thread of their own, so that this one sees Ctrl-C: no further
    // test starts, the tables say "interrupted", then the KeyboardInterrupt goes on. Nothing
    // below throws before the join (a thread abandoned at exit waits for ever meanwhile;
    // the exit hook joins the tests' thread then).
    ExperimentResult result;
    std::exception_ptr error;
    const bool started = work->start([&] {
        try {
            result = work->run->run();
        } catch (...) {
            error = std::current_exception();
        }
    });
    if (!started) throw Error("Python is exiting: the experiment was not started");
    std::optional<py::error_already_set> interrupt;
    while (!withoutGil([&] { return work->waitFor(kSignalPoll); })) {
        if (!interrupt && PyErr_CheckSignals() != 0) {
            interrupt.emplace();
            work->stop = true;
        }
    }
    withoutGil([&] { work->join(); });
    if (interrupt) throw *interrupt;
    if (error) std::rethrow_exception(error);
    // What the command wrote, as data: results.json (rows under "tests", with their
    // per-repeat details), plus where it lies and the run's own counts.
    nlohmann::ordered_json doc = nlohmann::ordered_json::parse(readTextFile((fs::path(work->run->out()) / "results.json").string()));
    doc["out"] = work->run->out();
    doc["failed"] = result.failed;
    doc["seconds"] = result.seconds;
    return toPython(doc).cast<py::dict>();
}

} // namespace binocle::python
