// SPDX-License-Identifier: MIT
// A rosbag2 bag written by Binocle: a folder holding one MCAP file (profile ros2, CDR,
// ros2msg schemas, zstd chunks) and the metadata.yaml that `ros2 bag` reads. What
// `binocle record --format mcap` and `binocle run --mcap` write through
// one class; the topics (under the namespace, default /binocle):
//   <ns>/left/image_raw, <ns>/right/image_raw       sensor_msgs/msg/Image (as captured)
//   <ns>/left/camera_info, <ns>/right/camera_info   sensor_msgs/msg/CameraInfo (plumb_bob)
//   <ns>/left/image_rect, <ns>/right/image_rect     sensor_msgs/msg/Image (run: rectified)
//   <ns>/disparity                                  stereo_msgs/msg/DisparityImage (run)
//   <ns>/points                                     sensor_msgs/msg/PointCloud2, ground frame (run)
//   <ns>/figures                                    diagnostic_msgs/msg/DiagnosticArray (run)
// Durability: each chunk is fsync'ed when written (mcap::Writer); a bag cut short is read
// up to its last complete chunk. close() writes the summary and the final metadata.yaml.
#pragma once

#include "core/calibration.hpp"

#include <binocle/mcap.hpp>

#include <opencv2/core.hpp>

#include <atomic>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace binocle {

struct RosbagOptions {
    std::string ros_namespace = "/binocle";
    std::string frame_id_left = "binocle_left_optical";
    std::string frame_id_right = "binocle_right_optical";
    std::string frame_id_ground = "binocle_ground";
    mcap::Compression compression = mcap::Compression::Zstd;
    int compression_level = 1;
};

// Refuses what ROS would: a namespace that breaks ROS 2's rule (rcl's namespace
// validation: "/" alone, or "/"-joined names of [A-Za-z0-9_] not starting with a digit, no
// "//", no trailing "/"), a frame id with spaces. Throws binocle::Error naming the option
// and the value.
void checkRosbagOptions(const RosbagOptions &options);
// Why `ns` is not a ROS 2 namespace ("'//x': it holds '//' ...; ROS 2 expects ..."), or
// empty: what --ros-namespace's validator answers.
std::string rosNamespaceRefusal(const std::string &ns);

class RosbagWriter {
public:
    // Creates the folder `dir` (which must not exist or be empty) and `<name>_0.mcap` in it,
    // where name is the folder's name. The calibration (YAML of core/calibration.hpp), when
    // given, goes out as CameraInfo with every image pair.
    RosbagWriter(const std::string &dir, const std::optional<StereoCalibration> &calibration,
                 const RosbagOptions &options = {});
    ~RosbagWriter(); // closes; errors are lost: call close()
    RosbagWriter(const RosbagWriter &) = delete;
    RosbagWriter &operator=(const RosbagWriter &) = delete;

    // A pair as captured (raw) or rectified: GRAY8 (mono8), GRAY16 (mono16), BGR8 (bgr8) or
    // RGB8 (`rgb`: rgb8) images; raw pairs get their CameraInfo beside them.
    void writePair(int64_t stampLeftNs, int64_t stampRightNs, const cv::Mat &left, const cv::Mat &right, bool rgb,
                   bool rectified = false);
    // CV_32F disparity of the left rectified image (invalid < 0 or non-finite: written as
    // ROS says, below min_disparity), with f (px) and T (baseline, m) for depth = f T / d.
    void writeDisparity(int64_t stampNs, const cv::Mat &disparity, double focalLengthPx, double baselineM,
                        double minDisparity, double maxDisparity);
    // Points (x, y, z float32, metres) in the ground frame.
    void writeCloud(int64_t stampNs, const std::vector<cv::Point3f> &points);
    // One DiagnosticStatus per group (e.g. an evaluator), one key/value per figure.
    void writeFigures(int64_t stampNs, const std::map<std::string, std::map<std::string, std::string>> &groups);

    // Writes the last chunk, the summary and footer, and metadata.yaml.
    void close();

    const std::string &dir() const { return dir_; }
    const std::string &file() const { return file_; }
    uint64_t messageCount() const;
    uint64_t bytesWritten() const;
    // The pairs (writePair calls) a reader of the bag recovers whole: those whose every
    // message lies in a chunk written whole (mcap::Writer::durableMessageCount). What a
    // recording may claim, on a full disk too. Counted after each writePair and at close,
    // so that asking (once per grabbed frame) never waits for a pair being encoded.
    int64_t durablePairs() const { return durablePairs_.load(); }

private:
    uint16_t channel(const std::string &topic, const char *type);
    void write(const std::string &topic, const char *type, int64_t stampNs, const std::vector<uint8_t> &bytes);
    void writeMetadataYaml();
    void countDurablePairs(); // with mutex_ held

    std::string dir_, file_;
    RosbagOptions options_;
    std::mutex mutex_;
    std::unique_ptr<mcap::Writer> writer_;
    std::optional<StereoCalibration> calibration_;
    std::map<std::string, std::pair<uint16_t, std::string>> channels_; // topic -> id, type
    std::map<std::string, uint64_t> counts_;
    std::deque<uint64_t> pairEnds_; // the message count after each pair not yet durable
    std::atomic<int64_t> durablePairs_{0};
    uint32_t sequence_ = 0;
    int64_t first_ = INT64_MAX, last_ = INT64_MIN;
    bool closed_ = false;
};

} // namespace binocle
