// SPDX-License-Identifier: MIT
// RosbagFrameWriter: a run's frames as ROS 2 messages (see rosbag_run_output.hpp).
#include "rosbag/rosbag_run_output.hpp"

#include "core/error.hpp"
#include "pipeline/pipeline.hpp"

#include <cmath>

namespace binocle {

RosbagFrameWriter::RosbagFrameWriter(const std::string &dir, const RosbagOptions &options)
    : writer_(dir, std::nullopt, options) {}

void RosbagFrameWriter::finish(nlohmann::ordered_json &) {
    writer_.close();
}

void RosbagFrameWriter::write(const FrameResult &r) {
    if (!r.calibration) throw Error("internal: a frame for the bag without the run's calibration");
    const StereoCalibration &calibration = *r.calibration;
    const int64_t stampL = r.frame ? r.frame->raw().timestamp_left_ns : static_cast<int64_t>(r.index);
    const int64_t stampR = r.frame ? r.frame->raw().timestamp_right_ns : stampL;
    if (!r.rectified_left.empty() && !r.rectified_right.empty())
        writer_.writePair(stampL, stampR, r.rectified_left, r.rectified_right, false, true);
    if (!r.disparity.empty()) {
        // max_disparity: the largest the frame holds (the matcher's range is the plugin's).
        double maxD = 0;
        for (int y = 0; y < r.disparity.rows; ++y) {
            const float *row = r.disparity.ptr<float>(y);
            for (int x = 0; x < r.disparity.cols; ++x)
                if (std::isfinite(row[x]) && row[x] > maxD) maxD = row[x];
        }
        writer_.writeDisparity(stampL, r.disparity, calibration.focalLengthPx(), calibration.baselineMm() / 1000.0, 0,
                               maxD);
    }
    std::vector<cv::Point3f> points(r.cloud.size());
    for (size_t i = 0; i < points.size(); ++i)
        points[i] = {r.cloud.xyz[3 * i] / 1000.0f, r.cloud.xyz[3 * i + 1] / 1000.0f, r.cloud.xyz[3 * i + 2] / 1000.0f};
    writer_.writeCloud(stampL, points);
    std::map<std::string, std::map<std::string, std::string>> groups;
    for (const auto &[evaluator, figures] : r.metrics.items())
        if (figures.is_object())
            for (const auto &[name, value] : figures.items()) groups[evaluator][name] = value.dump();
    if (!groups.empty()) writer_.writeFigures(stampL, groups);
}

} // namespace binocle
