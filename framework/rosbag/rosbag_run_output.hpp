// SPDX-License-Identifier: MIT
// `binocle run --out DIR --mcap`: every finished frame into DIR/bag/ (a rosbag2
// bag, RosbagWriter): the rectified pair, the disparity (stereo_msgs/DisparityImage), the
// cloud after the transforms (PointCloud2, metres, in the ground frame when a ground
// transform ran) and the evaluators' figures (DiagnosticArray).
#pragma once

#include "pipeline/pipeline.hpp"
#include "rosbag/rosbag_writer.hpp"

namespace binocle {

class RosbagRunOutput {
public:
    // Creates `dir` (which must not exist or be empty).
    explicit RosbagRunOutput(const std::string &dir, const RosbagOptions &options = {});
    // One finished frame, on the writer stage; `calibration` is the run's (for f and T).
    void onFrame(const FrameResult &frame, const StereoCalibration &calibration);
    void close() { writer_.close(); }
    const RosbagWriter &writer() const { return writer_; }

private:
    RosbagWriter writer_;
};

} // namespace binocle
