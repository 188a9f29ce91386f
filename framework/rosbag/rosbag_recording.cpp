// SPDX-License-Identifier: MIT
// RosbagRecordingWriter: the recorder's queue in front of one RosbagWriter.
#include "rosbag/rosbag_recording.hpp"

#include "files/atomic_file.hpp"
#include "core/error.hpp"
#include "pipeline/recorder.hpp"

#include <chrono>
#include <filesystem>

namespace fs = std::filesystem;

namespace binocle {

namespace {
std::optional<StereoCalibration> parseCalibration(const std::string &yaml) {
    if (yaml.empty()) return std::nullopt;
    return StereoCalibration::fromYaml(yaml, "the rig's calibration");
}

} // namespace

RosbagRecordingWriter::RosbagRecordingWriter(const std::string &dir, const std::string &calibrationYaml,
                                             const std::string &rigYaml, const RosbagOptions &rosbag,
                                             const RecordingWriterOptions &options)
    : options_(options) {
    const auto calibration = parseCalibration(calibrationYaml);
    bag_ = std::make_unique<RosbagWriter>(dir, calibration, rosbag);
    if (!calibrationYaml.empty()) writeFileAtomic((fs::path(dir) / "calibration.yml").string(), calibrationYaml);
    if (!rigYaml.empty()) writeFileAtomic((fs::path(dir) / "rig.yaml").string(), rigYaml);
    if (options_.queue_frames <= 0) options_.queue_frames = 32;
    stats_.threads = 1;
    stats_.queue_frames = options_.queue_frames;
    thread_ = std::thread([this] { work(); });
}

RosbagRecordingWriter::~RosbagRecordingWriter() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
    }
    workAvailable_.notify_all();
    thread_.join();
    try {
        bag_->close();
    } catch (...) {
        // finish() reports; a destructor cannot.
    }
}

void RosbagRecordingWriter::work() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
        workAvailable_.wait(lock, [&] { return stopping_ || !todo_.empty(); });
        if (todo_.empty()) return;
        Job job = std::move(todo_.front());
        todo_.pop_front();
        busy_ = true;
        lock.unlock();
        const auto t0 = std::chrono::steady_clock::now();
        std::string failure;
        try {
            if (error_.empty()) bag_->writePair(job.tl, job.tr, job.left, job.right, job.rgb);
        } catch (const std::exception &e) {
            failure = e.what();
        }
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        job = Job{};
        lock.lock();
        busy_ = false;
        stats_.write_ms += ms;
        if (!failure.empty() && error_.empty()) error_ = failure;
        roomAvailable_.notify_all();
        drained_.notify_all();
    }
}

bool RosbagRecordingWriter::submit(const LentFrame &frame, bool wait) {
    const binocle_stereo_frame &f = frame.raw();
    Job job;
    job.tl = f.timestamp_left_ns;
    job.tr = f.timestamp_right_ns;
    job.left = recordableView(f.left).clone(); // the source gets its buffers back at once
    job.right = recordableView(f.right).clone();
    job.rgb = f.left.format == BINOCLE_PIXEL_RGB8;
    std::unique_lock<std::mutex> lock(mutex_);
    if (!error_.empty()) throw Error(error_);
    if (closed_) throw Error("record: a pair submitted after the bag was closed");
    if (static_cast<int>(todo_.size()) >= options_.queue_frames) {
        if (!wait) return false;
        roomAvailable_.wait(lock, [&] { return static_cast<int>(todo_.size()) < options_.queue_frames || !error_.empty(); });
        if (!error_.empty()) throw Error(error_);
    }
    todo_.push_back(std::move(job));
    stats_.max_queued = std::max<int64_t>(stats_.max_queued, static_cast<int64_t>(todo_.size()));
    workAvailable_.notify_one();
    return true;
}

void RosbagRecordingWriter::finish() {
    std::unique_lock<std::mutex> lock(mutex_);
    drained_.wait(lock, [&] { return (todo_.empty() && !busy_) || !error_.empty(); });
    if (!closed_) {
        closed_ = true;
        lock.unlock();
        try {
            bag_->close();
            lock.lock();
            ++stats_.syncs;
        } catch (const std::exception &e) {
            lock.lock();
            if (error_.empty()) error_ = e.what();
        }
    }
    if (!error_.empty()) throw Error(error_);
}

int64_t RosbagRecordingWriter::frameCount() const {
    // What a reader recovers, not what was handed to the bag: a pair in the open chunk is
    // lost if the disk fills before the chunk is written.
    return bag_->durablePairs();
}

RecordingWriterStats RosbagRecordingWriter::stats() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stats_;
}

RecordingSinkFactory rosbagRecordingSink(const RosbagOptions &rosbag) {
    return [rosbag](const std::string &dir, const std::string &calibrationYaml, const std::string &rigYaml,
                    const RecordingWriterOptions &options) -> std::unique_ptr<RecordingSink> {
        return std::make_unique<RosbagRecordingWriter>(dir, calibrationYaml, rigYaml, rosbag, options);
    };
}

} // namespace binocle
