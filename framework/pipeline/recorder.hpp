// SPDX-License-Identifier: MIT
// Recording a rig's source into a RecordingSink (pipeline/recording_sink.hpp): by default
// a folder in the `recording` layout of plugins/replay/README.md (lossless PNG images,
// frames.csv, calibration.yml and rig.yaml). Images are encoded and written off the grab
// thread; a recording cut short is readable up to its last row.
#pragma once

#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"
#include "pipeline/recording_sink.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

namespace binocle {

// A lent image as a cv::Mat view (no copy) for a recording; refuses formats no recording
// holds (GRAY8, GRAY16, BGR8, RGB8 are recorded; RGB8 stays in RGB order here).
cv::Mat recordableView(const binocle_image &im);

// Writes one recording folder. Frames are copied by the caller's thread and handed to a pool
// of threads that encode each image to PNG and write it (temporary file, fsync, rename).
// The frames.csv rows are appended in the order the frames were submitted, in batches:
// the images of a batch are durable (data fsync'ed, folders fsync'ed for the renames)
// before its rows are written, and the rows are fsync'ed. A frame without its row does not
// exist; a row never names an image that a crash could lose.
class RecordingWriter : public RecordingSink {
public:
    // Creates `dir` (and its parents) and frames.csv with its header; writes calibration.yml
    // (when `calibrationYaml` is not empty) and rig.yaml (when `rigYaml` is not empty).
    // Refuses a folder that already holds anything, naming what it holds: nothing already
    // written is ever replaced.
    RecordingWriter(const std::string &dir, const std::string &calibrationYaml, const std::string &rigYaml,
                    const RecordingWriterOptions &options = {});
    // Finishes the frames submitted (errors are dropped: call finish() to see them).
    ~RecordingWriter() override;
    RecordingWriter(const RecordingWriter &) = delete;
    RecordingWriter &operator=(const RecordingWriter &) = delete;

    // Writes one frame and returns when its row is durable. left, right: GRAY8 (CV_8UC1),
    // GRAY16 (CV_16UC1), BGR8 (CV_8UC3) or RGB8 (CV_8UC3, `rgb` true: stored as the same
    // colours). Throws binocle::Error naming the file on any write failure.
    void append(uint64_t sequence, int64_t timestampLeftNs, int64_t timestampRightNs, const cv::Mat &left,
                const cv::Mat &right, bool rgb = false);
    // A frame as a source lent it.
    void append(const LentFrame &frame);

    // Copies the frame's images (the source may have its buffers back at once) and queues
    // them. When the queue is full: waits for room when `wait`, else returns false and
    // queues nothing. Throws the first write failure of an earlier frame.
    bool submit(const LentFrame &frame, bool wait) override;
    // The same with images the writer takes over (they must not be written to afterwards).
    bool submit(uint64_t sequence, int64_t timestampLeftNs, int64_t timestampRightNs, cv::Mat left, cv::Mat right, bool rgb,
                bool wait);
    // Waits until every frame submitted is written and its row durable; throws the first
    // write failure (frames listed before it stay readable).
    void finish() override;

    // Frames whose rows are in frames.csv and durable.
    int64_t frameCount() const override;
    const std::string &dir() const { return dir_; }
    RecordingWriterStats stats() const override;

private:
    struct Pool;
    std::string dir_;
    std::unique_ptr<Pool> pool_;
};

struct RecordOptions {
    int64_t max_frames = -1;         // pairs taken from the source; < 0: until it ends (or `stop` is set)
    int32_t grab_timeout_ms = 5000;
    bool progress = true;            // a progress line on stderr
    const std::atomic<bool> *stop = nullptr; // set from elsewhere (a signal) to end cleanly
    // When the writers fall behind: wait (the source waits too), or drop the pair and count
    // it. Unset: drop for a live source (its statistics say `live: true`: a camera does not
    // wait, and a grab thread that waits only moves the loss into the camera's buffers),
    // wait for any other (files, simulation: nothing is lost).
    std::optional<bool> drop_when_behind;
    RecordingWriterOptions writer;
    // Where the pairs go: empty, the folder (folderRecordingSink); the command may choose
    // another (`record --format mcap`: rosbag/rosbag_recording.hpp).
    RecordingSinkFactory sink;
};

struct RecordResult {
    int64_t frames = 0;            // pairs written (rows in frames.csv)
    int64_t grabbed = 0;           // pairs taken from the source
    int64_t dropped_by_writer = 0; // pairs taken but not written: the writers were behind
    bool dropped_when_behind = false;
    double seconds = 0;
    std::string source_statistics; // YAML of the source, when it gives any
    RecordingWriterStats writer;
    std::string status = "complete"; // complete | interrupted | error
    std::string error;               // empty when the run ended normally
};

// The folder of PNG pairs and frames.csv: a RecordingWriter.
RecordingSinkFactory folderRecordingSink();

// Records rig.source into `dir` through options.sink. The calibration written is the rig's
// calibration file, else the source's own, else none. The grabs are the pipeline's
// (pipeline/source_grab.hpp), and so is the answer to whether the source is live. A failure of the source after the recording has started
// ends the run and is returned in `error` (the frames already written stay readable);
// failures before (folder refused, source cannot open) are thrown as binocle::Error.
// `onFrame` gets the number of pairs taken from the source so far.
// At the end the folder gets summary.json (recordingSummary) beside what the sink wrote.
RecordResult recordRig(const RigConfig &rig, const std::string &dir, const RecordOptions &options,
                       const std::function<void(int64_t frames)> &onFrame = {});

// The run's figures as JSON: pairs taken, written and lost, and where each was lost: in the
// cameras or the transport, in pairing (from the source's statistics), or by the writers.
nlohmann::ordered_json recordingSummary(const RecordResult &result);

} // namespace binocle
