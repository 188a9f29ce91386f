// SPDX-License-Identifier: MIT
// What `binocle record` writes a source's pairs into: the one interface of the recorder's
// outputs. The folder of PNG pairs and frames.csv (RecordingWriter, pipeline/recorder.hpp)
// and the rosbag2 bag (RosbagRecordingWriter, rosbag/rosbag_recording.hpp) implement it;
// the command chooses one (RecordOptions::sink), the recorder's loop names neither.
#pragma once

#include "host/plugin_host.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace binocle {

// How a recording sink spreads its work.
struct RecordingWriterOptions {
    int threads = 0;            // threads that encode and write images; 0 = two per core, 4..16
    int png_compression = 1;    // zlib level 0..9; 1: lossless all the same, several times faster than 6
    int queue_frames = 0;       // frames copied and waiting for a thread; 0 = 8 per thread
    int sync_batch_frames = 16; // frames.csv rows made durable together ...
    int sync_interval_ms = 200; // ... or after this long, whichever comes first
};

// What a recording sink did, for the summary.
struct RecordingWriterStats {
    int threads = 0;
    int png_compression = 0;
    int queue_frames = 0;
    int64_t max_queued = 0; // most frames waiting at once
    int64_t syncs = 0;      // batches of rows made durable
    double encode_ms = 0;   // total PNG encoding time, all threads
    double write_ms = 0;    // total time writing and fsync'ing image files, all threads
};

// Pairs as a source lent them, in order, from the recorder's thread. A sink copies what it
// keeps (the source has its buffers back once submit returns) and writes off that thread.
class RecordingSink {
public:
    virtual ~RecordingSink() = default;
    // Copies the frame's images and queues them. When the queue is full: waits for room
    // when `wait`, else returns false and queues nothing. Throws the first write failure of
    // an earlier frame.
    virtual bool submit(const LentFrame &frame, bool wait) = 0;
    // Writes every pair submitted and makes it durable; throws the first write failure
    // (pairs made durable before it stay readable).
    virtual void finish() = 0;
    // Pairs a reader of the recording recovers whole (a recording's claim, on a full disk too).
    virtual int64_t frameCount() const = 0;
    virtual RecordingWriterStats stats() const = 0;
};

// Makes the sink of a recording into `dir` once the calibration is known (the rig's file,
// else the source's own; YAML of core/calibration.hpp, empty: none) with the rig as
// resolved (`rigYaml`). Refuses a `dir` that already holds anything.
using RecordingSinkFactory = std::function<std::unique_ptr<RecordingSink>(
    const std::string &dir, const std::string &calibrationYaml, const std::string &rigYaml,
    const RecordingWriterOptions &options)>;

} // namespace binocle
