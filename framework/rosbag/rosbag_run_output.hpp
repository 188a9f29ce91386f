// SPDX-License-Identifier: MIT
// `binocle run --out DIR --mcap`: every finished frame into DIR/bag/ (a rosbag2 bag,
// RosbagWriter): the rectified pair, the disparity (stereo_msgs/DisparityImage), the
// cloud after the transforms (PointCloud2, metres, in the ground frame when a ground
// transform ran) and the evaluators' figures (DiagnosticArray). A FrameWriter
// (pipeline/frame_writer.hpp) as the run's folder is: the command hands it to the pipeline
// in RunOptions::writers, and the writer stage calls it after the folder's.
#pragma once

#include "pipeline/frame_writer.hpp"
#include "rosbag/rosbag_writer.hpp"

namespace binocle {

class RosbagFrameWriter : public FrameWriter {
public:
    // Creates `dir` (which must not exist or be empty).
    explicit RosbagFrameWriter(const std::string &dir, const RosbagOptions &options = {});
    // One finished frame, on the writer stage (f and T from the frame's calibration).
    void write(const FrameResult &frame) override;
    // Closes the bag (summary, footer, metadata.yaml); a failure fails the run.
    void finish(nlohmann::ordered_json &summary) override;
    const RosbagWriter &bag() const { return writer_; }

private:
    RosbagWriter writer_;
};

} // namespace binocle
