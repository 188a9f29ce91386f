// SPDX-License-Identifier: MIT
// binocle.experiment() (experiment_call.hpp): the arguments checked, the tests on a
// thread of their own, the experiment ended with the interpreter.
#include "python/experiment_call.hpp"

#include "python/arguments.hpp"
#include "python/convert.hpp"
#include "python/lifecycle.hpp"

#include "files/atomic_file.hpp"
#include "core/output_folder.hpp"
#include "experiment/experiment.hpp"

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
    std::optional<OutputFolder> folder; // claimed before the tests start
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
    // Waits for the tests' thread, then lets go of the output folder (its lock).
    void join() {
        std::lock_guard<std::mutex> lock(joining_);
        if (worker_.joinable()) worker_.join();
        folder.reset();
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
    const std::string path = *pathText(file, "file");
    const std::vector<std::string> overrides = setTexts(set);
    const std::optional<std::string> outText = pathText(out, "out", "out/<the experiment's name>");
    ExperimentOptions options;
    options.only = textList(tests, "tests");
    options.replace = flag(force, "force");
    options.progress = flag(progress, "progress");
    auto work = std::make_shared<ExperimentWork>();
    keepUntilExit(work);
    options.stop = &work->stop;
    auto host = std::make_unique<PluginHost>();
    std::optional<Experiment> e;
    withoutGil([&] {
        // Everything is checked before the first test runs (as `binocle experiment`).
        e.emplace(loadExperiment(path, *host, overrides));
        options.out_dir = outText ? *outText : "out/" + e->name;
        work->folder.emplace(options.out_dir, OutputClaim{OutputKind::Experiment, options.replace, "binocle.experiment"});
    });
    // The tests run on a thread of their own, so that this one sees Ctrl-C: no further
    // test starts, the tables say "interrupted", then the KeyboardInterrupt goes on. Nothing
    // below throws before the join (a thread abandoned at exit waits for ever meanwhile;
    // the exit hook joins the tests' thread then).
    ExperimentResult result;
    std::exception_ptr error;
    const bool started = work->start([&] {
        try {
            result = runExperiment(*e, *host, options);
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
    withoutGil([&] {
        work->join();
        host.reset();
    });
    if (interrupt) throw *interrupt;
    if (error) std::rethrow_exception(error);
    // What the command wrote, as data: results.json (rows under "tests", with their
    // per-repeat details), plus where it lies and the run's own counts.
    nlohmann::ordered_json doc = nlohmann::ordered_json::parse(readTextFile((fs::path(options.out_dir) / "results.json").string()));
    doc["out"] = options.out_dir;
    doc["failed"] = result.failed;
    doc["seconds"] = result.seconds;
    return toPython(doc).cast<py::dict>();
}

} // namespace binocle::python
