// SPDX-License-Identifier: MIT
// binocle.Run: the frames of a run, from any thread (run.hpp).
#include "python/run.hpp"

#include "core/error.hpp"

namespace binocle::python {

void RunState::start(const std::shared_ptr<RunState> &state, std::shared_ptr<const LoadedRig> rig, const StreamOptions &options) {
    keepUntilExit(state);
    withoutGil([&] {
        // Held while the run starts: the exit hook, which ends it, waits for that.
        std::lock_guard<std::mutex> lock(state->mutex_);
        if (state->ended_) throw Error("Python is exiting: no run starts now");
        state->stream_ = std::make_shared<RunStream>(std::move(rig), options);
    });
}

std::shared_ptr<RunStream> RunState::stream() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stream_;
}

void RunState::close(bool raise) {
    std::lock_guard<std::mutex> one(closing_);
    std::shared_ptr<RunStream> s = stream();
    if (!s) return;
    if (!raise) s->stop();
    std::exception_ptr error;
    try {
        s->finish();
    } catch (...) {
        error = std::current_exception();
    }
    {
        std::lock_guard<std::mutex> lock(mutex_);
        summary_ = s->summary();
        stream_.reset();
    }
    if (raise && error) std::rethrow_exception(error);
}

void RunState::endAtExit() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        ended_ = true;
    }
    close(false);
}

nlohmann::ordered_json RunState::summary() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return summary_;
}

Run::Run(std::shared_ptr<const LoadedRig> rig, const StreamOptions &options) : state_(std::make_shared<RunState>()) {
    RunState::start(state_, std::move(rig), options);
}

Run::~Run() {
    if (state_->forkedAway()) {
        // The run's threads are the parent's: nothing here may join or lock them.
        new std::shared_ptr<RunState>(std::move(state_)); // NOLINT: left behind on purpose
        return;
    }
    withoutGil([&] { state_->close(false); });
}

void Run::refuseInForkedChild() const {
    if (state_->forkedAway())
        throw Error("this run was started by process " + std::to_string(state_->pid()) + ", and this is a child it forked (" +
                    std::to_string(::getpid()) + "): the run's threads are not here; start a run in this process "
                    "(docs/python.md, \"Threads, fork and exit\")");
}

Frame Run::next() {
    refuseInForkedChild();
    std::shared_ptr<RunStream> stream = state_->stream();
    if (!stream) throw py::stop_iteration();
    for (;;) {
        std::shared_ptr<OwnedFrame> frame;
        const RunStream::Next n = withoutGil([&] { return stream->next(frame, kSignalPoll); });
        if (n == RunStream::Next::Frame) return toFrame(std::move(frame));
        if (n == RunStream::Next::End) {
            stream.reset();
            withoutGil([&] { state_->close(true); });
            throw py::stop_iteration();
        }
        if (PyErr_CheckSignals() != 0) {
            // Ctrl-C: the run stops as `binocle run` does on SIGINT (frames in flight
            // finished, summary written, status interrupted), then the
            // KeyboardInterrupt goes on.
            py::error_already_set pending;
            stream.reset();
            withoutGil([&] { state_->close(false); });
            throw pending;
        }
    }
}

void Run::close() {
    // In a forked child there is nothing of the run to stop (the parent's goes on).
    if (state_->forkedAway()) return;
    withoutGil([&] { state_->close(false); });
}

py::object Run::summary() const {
    refuseInForkedChild();
    const nlohmann::ordered_json s = state_->summary();
    return s.is_null() ? py::none() : toPython(s);
}

} // namespace binocle::python
