// SPDX-License-Identifier: MIT
// `binocle record --format mcap`: the recorder's sink for a rosbag2 bag, a RecordingSink
// (pipeline/recording_sink.hpp) as the folder's RecordingWriter is, so that the recorder
// drives either: submit() copies the pair and queues it (or refuses it when the queue is
// full and the caller does not wait), one thread turns pairs into Image + CameraInfo
// messages of the bag (RosbagWriter), finish() writes what is queued and closes the bag
// (summary, footer, metadata.yaml). rig.yaml and calibration.yml go beside the bag, as in
// a folder recording.
#pragma once

#include "pipeline/recording_sink.hpp"
#include "rosbag/rosbag_writer.hpp"

#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

namespace binocle {

class RosbagRecordingWriter : public RecordingSink {
public:
    RosbagRecordingWriter(const std::string &dir, const std::string &calibrationYaml, const std::string &rigYaml,
                          const RosbagOptions &rosbag, const RecordingWriterOptions &options = {});
    ~RosbagRecordingWriter() override;
    RosbagRecordingWriter(const RosbagRecordingWriter &) = delete;
    RosbagRecordingWriter &operator=(const RosbagRecordingWriter &) = delete;

    bool submit(const LentFrame &frame, bool wait) override;
    // Writes every pair submitted and closes the bag; throws the first write failure.
    void finish() override;
    int64_t frameCount() const override; // the pairs a reader recovers (RosbagWriter::durablePairs)
    RecordingWriterStats stats() const override;
    const RosbagWriter &bag() const { return *bag_; }

private:
    struct Job {
        int64_t tl = 0, tr = 0;
        cv::Mat left, right;
        bool rgb = false;
    };
    void work();

    std::unique_ptr<RosbagWriter> bag_;
    RecordingWriterOptions options_;
    mutable std::mutex mutex_;
    std::condition_variable workAvailable_, roomAvailable_, drained_;
    std::deque<Job> todo_;
    bool busy_ = false, stopping_ = false, closed_ = false;
    std::string error_;
    RecordingWriterStats stats_;
    std::thread thread_;
};

// The bag as the recorder's sink (RecordOptions::sink); the bag refuses `rosbag` when
// checkRosbagOptions does.
RecordingSinkFactory rosbagRecordingSink(const RosbagOptions &rosbag);

} // namespace binocle
