// SPDX-License-Identifier: MIT
// Private to the pipeline: the state one run shares between its stage threads (pipeline.cpp
// starts and ends the run; pipeline_stages.cpp is what each stage thread does), and an
// evaluator as the pipeline holds it.
#pragma once

#include "pipeline/pipeline.hpp"
#include "pipeline/frame_writer.hpp"
#include "pipeline/plugin_instances.hpp"
#include "pipeline/stage_queue.hpp"
#include "pipeline/stage_times.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace binocle {

using Clock = std::chrono::steady_clock;

inline double secondsSince(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// An evaluator and where its sink puts the figures of the call in progress (set around
// each evaluate() and finish()).
struct Pipeline::EvaluatorSlot {
    std::string name;
    std::unique_ptr<Evaluator> evaluator;
    nlohmann::ordered_json *target = nullptr; // where its figures go right now
    std::vector<std::pair<std::string, double>> *flat = nullptr;
};

// A frame on its way through the stages; its buffers are reused by later frames.
struct Pipeline::Job {
    std::unique_ptr<LentFrame> frame;
    Clock::time_point grabbed;
    FrameResult r;
    bool failed = false;
};

struct Pipeline::RunState {
    struct Grabbed {
        std::unique_ptr<LentFrame> frame;
        Clock::time_point at;
        double seconds = 0; // in the source's grab
    };
    RunState(const RunOptions &o, size_t sourceDepth, size_t stageDepth)
        : options(o), sourceQueue(sourceDepth), matched(stageDepth), clouded(stageDepth), evaluated(stageDepth) {}

    const RunOptions &options;
    RuntimeOptions::Policy policy = RuntimeOptions::Policy::Lossless;
    SourceQueue<Grabbed> sourceQueue;
    OrderedQueue<std::unique_ptr<Job>> matched, clouded, evaluated;

    std::mutex poolMutex;
    std::condition_variable poolReady;
    std::vector<std::unique_ptr<Job>> pool;

    // Frames through the writer (done or failed), for between_frames' drain.
    std::mutex doneMutex;
    std::condition_variable doneCv;
    int64_t finished = 0;

    std::atomic<bool> aborted{false};
    std::mutex failMutex;
    std::string failure;

    // The writer stage's, read after it ends.
    std::unique_ptr<FrameWriter> folder; // out_dir's
    std::vector<FrameWriter *> writers;  // the folder's, then the caller's
    RunTimes times;
    int64_t written = 0; // frames through every stage

    // Written by the acquire stage, read after it is joined.
    int64_t grabbed = 0, droppedByPolicy = 0, sourceErrors = 0, recoveries = 0;
    bool endOfStream = false;
    std::string lastSourceError;

    bool stopRequested() const { return options.stop && options.stop->load(); }
    // A failed stage ends the run: frames behind it are not finished. A failed source
    // (`processing` false) only ends acquisition: the frames it delivered are.
    void fail(const std::string &what, bool processing = true) {
        std::lock_guard<std::mutex> lock(failMutex);
        if (failure.empty()) failure = what;
        if (processing) aborted = true;
    }
    std::unique_ptr<Job> takeJob() {
        std::unique_lock<std::mutex> lock(poolMutex);
        poolReady.wait(lock, [&] { return !pool.empty(); });
        std::unique_ptr<Job> job = std::move(pool.back());
        pool.pop_back();
        return job;
    }
    void giveJob(std::unique_ptr<Job> job) {
        std::lock_guard<std::mutex> lock(poolMutex);
        pool.push_back(std::move(job));
        poolReady.notify_one();
    }
};

} // namespace binocle
