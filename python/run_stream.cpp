// SPDX-License-Identifier: MIT
// The run's thread and the bounded queue between the pipeline's writer stage and Python.
#include "python/run_stream.hpp"

#include "files/atomic_file.hpp"

#include <filesystem>
#include <spdlog/spdlog.h>

namespace fs = std::filesystem;

namespace binocle::python {

RunStream::RunStream(std::shared_ptr<const LoadedRig> rig, const StreamOptions &options)
    : rig_(std::move(rig)), options_(options) {
    if (options_.depth < 1) options_.depth = 1;
    // Made here, on the caller's thread: a plugin that refuses its settings, or an output
    // folder that is taken, is an error of the call that asked for the run.
    app::RunRequest request;
    request.caller.command = "binocle.Rig.run";
    request.frames = options_.max_frames;
    request.out = options_.out_dir;
    request.force = options_.force;
    request.progress = options_.progress;
    request.stop = &stop_;
    run_ = std::make_unique<app::RigRun>(rig_->rig, *rig_->host, request);
    thread_ = std::thread([this] { work(); });
}

RunStream::~RunStream() {
    stop();
    try {
        finish();
    } catch (const std::exception &e) {
        // Nobody is left to raise it to: the frames were not wanted any more.
        spdlog::warn("a run that was given up failed: {}", e.what());
    }
}

void RunStream::work() {
    nlohmann::ordered_json summary;
    std::exception_ptr error;
    try {
        summary = run_->run([this](const FrameResult &r) { onFrame(r); }).summary;
    } catch (...) {
        error = std::current_exception();
        // A failed run throws after writing its summary: with an output folder, that is
        // the summary the caller sees.
        if (!options_.out_dir.empty()) {
            try {
                summary = nlohmann::ordered_json::parse(readTextFile((fs::path(options_.out_dir) / "summary.json").string()));
            } catch (const std::exception &) {
            }
        }
    }
    std::lock_guard<std::mutex> lock(mutex_);
    summary_ = std::move(summary);
    error_ = error;
    done_ = true;
    changed_.notify_all();
}

void RunStream::onFrame(const FrameResult &r) {
    {
        // Waits for room before copying: a consumer that is behind holds the pipeline back
        // (as a slow writer does), and nothing is copied for a run given up.
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return stop_.load() || queue_.size() < options_.depth; });
        if (stop_) return;
    }
    auto f = std::make_shared<OwnedFrame>();
    f->index = r.index;
    f->sequence = r.sequence;
    r.rectified_left.copyTo(f->left);
    r.rectified_right.copyTo(f->right);
    r.disparity.copyTo(f->disparity);
    f->xyz.assign(r.cloud.xyz.begin(), r.cloud.xyz.begin() + static_cast<std::ptrdiff_t>(3 * r.cloud.size()));
    if (r.cloud.rgb.size() >= 3 * r.cloud.size())
        f->rgb.assign(r.cloud.rgb.begin(), r.cloud.rgb.begin() + static_cast<std::ptrdiff_t>(3 * r.cloud.size()));
    f->cloud_frame = r.cloud.frame;
    f->valid_pixel_ratio = r.valid_pixel_ratio;
    f->seconds = r.seconds;
    f->latency_s = r.latency_s;
    f->metrics = r.metrics;
    f->figures = r.figures;
    std::lock_guard<std::mutex> lock(mutex_);
    if (stop_) return;
    queue_.push_back(std::move(f));
    changed_.notify_all();
}

RunStream::Next RunStream::next(std::shared_ptr<OwnedFrame> &frame, std::chrono::milliseconds wait) {
    std::unique_lock<std::mutex> lock(mutex_);
    // A stopped run has no frame to give (stop() dropped the queue): its consumer learns
    // the end at once, without waiting for the frames in flight (finish() does).
    changed_.wait_for(lock, wait, [&] { return !queue_.empty() || done_ || stop_; });
    if (!queue_.empty()) {
        frame = std::move(queue_.front());
        queue_.pop_front();
        changed_.notify_all();
        return Next::Frame;
    }
    return done_ || stop_ ? Next::End : Next::Waiting;
}

void RunStream::stop() {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    queue_.clear();
    changed_.notify_all();
}

void RunStream::finish() {
    {
        // Two threads may finish one run (one closes it while another iterates): one joins.
        std::lock_guard<std::mutex> lock(joining_);
        if (!joined_) {
            if (thread_.joinable()) thread_.join();
            joined_ = true;
            run_->release(); // the lock of the output folder goes once the summary is written
        }
    }
    std::exception_ptr error;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        std::swap(error, error_);
    }
    if (error) std::rethrow_exception(error);
}

nlohmann::ordered_json RunStream::summary() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return summary_;
}

} // namespace binocle::python
