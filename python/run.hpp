// SPDX-License-Identifier: MIT
// binocle.Run, the iterator of Rig.run(): usable from any thread (each frame goes to one
// caller; close() from another thread ends the iteration), ended when the interpreter
// exits, refused in a forked child.
#pragma once

#include "python/convert.hpp"
#include "python/lifecycle.hpp"
#include "python/run_stream.hpp"

namespace binocle::python {

// What a Run object and the exit hook share: the run's stream while it goes, then its
// summary.
class RunState final : public Ending {
public:
    // Starts the run (without the GIL); `state` is registered first, so that the exit
    // hook waits for a run being started.
    static void start(const std::shared_ptr<RunState> &state, std::shared_ptr<const LoadedRig> rig, const StreamOptions &options);
    std::shared_ptr<RunStream> stream() const;
    // Without the GIL: stops the run (unless `raise`: its frames are all taken), waits for
    // its end and keeps its summary; rethrows the run's error when `raise`. A second
    // caller waits for the first.
    void close(bool raise);
    void endAtExit() override;
    nlohmann::ordered_json summary() const;

private:
    std::mutex closing_; // one close at a time
    mutable std::mutex mutex_;
    std::shared_ptr<RunStream> stream_;
    nlohmann::ordered_json summary_;
    bool ended_ = false; // by the exit hook: no stream may start
};

class Run {
public:
    Run(std::shared_ptr<const LoadedRig> rig, const StreamOptions &options);
    ~Run();
    Run(const Run &) = delete;
    Run &operator=(const Run &) = delete;

    Frame next();
    void close();
    py::object summary() const;

private:
    void refuseInForkedChild() const;
    std::shared_ptr<RunState> state_;
};

} // namespace binocle::python
