// SPDX-License-Identifier: MIT
// Recording a rig's source to a folder in the `recording` layout of plugins/replay/README.md:
// lossless PNG images, frames.csv, calibration.yml and rig.yaml. Every frame is durable
// before the next one starts, so a recording cut short is readable up to its last frame.
#pragma once

#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <string>

namespace binocle {

// Writes one recording folder. Each frame: both images to a temporary file, fsync, rename;
// then its frames.csv line, flushed and fsync'ed. A frame without its line does not exist.
class RecordingWriter {
public:
    // Creates `dir` (and its parents) and frames.csv with its header; writes calibration.yml
    // (when `calibrationYaml` is not empty) and rig.yaml (when `rigYaml` is not empty).
    // Refuses a folder that already holds anything, naming what it holds: nothing already
    // written is ever replaced.
    RecordingWriter(const std::string &dir, const std::string &calibrationYaml, const std::string &rigYaml);
    ~RecordingWriter();
    RecordingWriter(const RecordingWriter &) = delete;
    RecordingWriter &operator=(const RecordingWriter &) = delete;

    // left, right: GRAY8 (CV_8UC1), BGR8 (CV_8UC3) or RGB8 (CV_8UC3, `rgb` true: stored as
    // the same colours). Throws binocle::Error naming the file on any write failure.
    void append(uint64_t sequence, int64_t timestampLeftNs, int64_t timestampRightNs, const cv::Mat &left,
                const cv::Mat &right, bool rgb = false);
    // A frame as a source lent it.
    void append(const LentFrame &frame);

    int64_t frameCount() const { return frames_; }
    const std::string &dir() const { return dir_; }

    // Image file of a frame, relative to the folder: "left/000017.png".
    static std::string imagePath(const std::string &side, uint64_t sequence);

private:
    std::string dir_;
    int csvFd_ = -1;
    int64_t frames_ = 0;
};

struct RecordOptions {
    int64_t max_frames = -1;         // < 0: until the source ends (or `stop` is set)
    int32_t grab_timeout_ms = 5000;
    bool progress = true;            // a progress line on stderr
    const std::atomic<bool> *stop = nullptr; // set from elsewhere (a signal) to end cleanly
};

struct RecordResult {
    int64_t frames = 0;
    double seconds = 0;
    std::string source_statistics; // YAML of the source, when it gives any
    std::string error;             // empty when the run ended normally
};

// Records rig.source into `dir`. The calibration written is the rig's calibration file,
// else the source's own, else none. A failure of the source after the recording has started
// ends the run and is returned in `error` (the frames already written stay readable);
// failures before (folder refused, source cannot open) are thrown as binocle::Error.
RecordResult recordRig(const RigConfig &rig, const std::string &dir, const RecordOptions &options,
                       const std::function<void(int64_t frames)> &onFrame = {});

} // namespace binocle
