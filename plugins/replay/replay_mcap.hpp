// SPDX-License-Identifier: MIT
// The `mcap` layout of replay: stereo pairs from a rosbag2 MCAP bag (a .mcap file or a
// rosbag2 folder with metadata.yaml), two image topics paired by header stamp, decoded
// from sensor_msgs/msg/Image or CompressedImage; the bag's CameraInfo as calibration.
// Part of binocle_replay_files (linked by the plugin, the tests and tests/fuzz).
#pragma once

#include <binocle/mcap.hpp>
#include <binocle/plugin.hpp>
#include <binocle/ros2_messages.hpp>

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace binocle::replay {

struct McapSettings {
    std::string bag;                  // a .mcap file or a rosbag2 folder
    std::string leftTopic, rightTopic; // empty: the `*/left/X` + `*/right/X` pair of the bag
    double pairToleranceMs = 5;       // largest |stamp_left - stamp_right| of a pair
    double startS = 0;                // from the bag's first message
    double durationS = 0;             // 0: to the end
};

// A sensor_msgs Image as 8-bit BGR (gray = false) or GRAY: mono8/16, rgb8, bgr8, rgba8,
// bgra8, bayer_*8/16 (demosaiced); 16-bit values are scaled to 8 bits (v / 256), as the
// other layouts read 16-bit PNG. `where` names the file, topic and offset in errors.
cv::Mat imageToMat(const ros2::Image &image, bool gray, const std::string &where);
// A sensor_msgs CompressedImage (jpeg, png): its header checked before decoding.
cv::Mat compressedToMat(const ros2::CompressedImage &image, bool gray, const std::string &where);

class McapPairs {
public:
    struct Pair {
        int64_t stampLeftNs = 0, stampRightNs = 0;
        uint64_t logTimeNs = 0;
        size_t left = 0, right = 0; // indices in messages_
    };

    // Opens the bag, picks the topics, reads every header stamp of the two topics in the
    // time window and pairs them. Throws sdk::Error naming the file and topic.
    McapPairs(const McapSettings &settings, const sdk::Host &host);

    const std::vector<Pair> &pairs() const { return pairs_; }
    // Decodes pair `i` into `left` and `right` (GRAY8 or BGR8).
    void decode(size_t i, bool gray, cv::Mat &left, cv::Mat &right) const;
    // OpenCV FileStorage YAML (framework/core/calibration.hpp) from the first CameraInfo of
    // each side's camera_info topic; empty when the bag has none (`why` says why).
    std::string calibrationYaml(std::string &why) const;

    const std::string &leftTopic() const { return topics_[0]; }
    const std::string &rightTopic() const { return topics_[1]; }
    size_t unpaired(int side) const { return unpaired_[side]; }
    // "topic (type, N messages)" of every channel, for messages and statistics.
    std::string topicList() const;
    const std::string &files() const { return fileList_; }

private:
    struct Message {
        size_t file = 0;
        size_t chunk = SIZE_MAX; // index in the file's chunks(); SIZE_MAX: outside chunks
        int64_t recordOffset = 0;
        int64_t stampNs = 0;
        uint64_t logTimeNs = 0;
        bool compressed = false;
    };
    void openFiles(const std::string &bag);
    void pickTopics(const McapSettings &s);
    void index(const McapSettings &s);
    void pair(const McapSettings &s);
    cv::Mat decodeOne(const Message &m, int side, bool gray) const;
    std::string where(const Message &m, int side) const;

    std::vector<std::unique_ptr<mcap::Reader>> readers_;
    std::string fileList_;
    std::string topics_[2];
    std::vector<Message> messages_;
    std::vector<size_t> leftIds_, rightIds_; // indices in messages_
    std::vector<Pair> pairs_;
    size_t unpaired_[2] = {0, 0};
};

// True when `folder` is a rosbag2 folder (metadata.yaml or .mcap files) or `path` an .mcap file.
bool isMcapBag(const std::string &path);

} // namespace binocle::replay
