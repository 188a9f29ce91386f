// SPDX-License-Identifier: MIT
// RosbagWriter: Binocle's images, disparities, clouds and figures as a rosbag2 MCAP bag.
#include "rosbag/rosbag_writer.hpp"

#include "core/error.hpp"
#include "core/output_folder.hpp"
#include "files/atomic_file.hpp"

#include <binocle/ros2_messages.hpp>
#include <binocle/text.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace fs = std::filesystem;

namespace binocle {

namespace {

bool rosName(const std::string &s, bool allowSlash) {
    if (s.empty()) return false;
    for (char c : s)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || (allowSlash && c == '/'))) return false;
    return s.find("//") == std::string::npos;
}

std::string encodingOf(const cv::Mat &m, bool rgb) {
    switch (m.type()) {
    case CV_8UC1: return "mono8";
    case CV_16UC1: return "mono16";
    case CV_8UC3: return rgb ? "rgb8" : "bgr8";
    default:
        throw Error("rosbag: an image of OpenCV type " + std::to_string(m.type()) +
                    "; expected GRAY8, GRAY16, BGR8 or RGB8");
    }
}

ros2::Image imageMessage(const cv::Mat &m, const std::string &encoding, int64_t stampNs, const std::string &frame) {
    ros2::Image img;
    img.header.stamp = ros2::Time::fromNs(stampNs);
    img.header.frame_id = frame;
    img.width = static_cast<uint32_t>(m.cols);
    img.height = static_cast<uint32_t>(m.rows);
    img.encoding = encoding;
    img.step = static_cast<uint32_t>(m.cols * m.elemSize());
    img.data = m.data;
    img.size = img.step * static_cast<size_t>(m.rows);
    return img;
}

std::array<double, 9> arr9(const cv::Mat &m) {
    std::array<double, 9> a{};
    cv::Mat d;
    m.convertTo(d, CV_64F);
    for (int i = 0; i < 9; ++i) a[i] = d.at<double>(i / 3, i % 3);
    return a;
}

} // namespace

// ROS 2's rule for a namespace (rcl's rmw_validate_namespace): "/" alone, or "/" followed
// by tokens joined by single '/', each of letters, digits and '_' and not starting with a
// digit; no trailing '/'; at most 255 characters. Empty when `ns` keeps it, else why not.
std::string namespaceProblem(const std::string &ns) {
    if (ns.empty()) return "it is empty";
    if (ns[0] != '/') return "it does not start with '/'";
    if (ns.size() > 255) return "it is longer than 255 characters";
    if (ns == "/") return "";
    if (ns.back() == '/') return "it ends with '/'";
    size_t start = 1;
    while (start <= ns.size()) {
        const size_t end = std::min(ns.find('/', start), ns.size());
        const std::string token = ns.substr(start, end - start);
        if (token.empty()) return "it holds '//' (an empty name)";
        if (std::isdigit(static_cast<unsigned char>(token[0]))) return "the name '" + token + "' starts with a digit";
        if (!rosName(token, false)) return "the name '" + sdk::printable(token) + "' holds a character other than letters, digits and '_'";
        start = end + 1;
    }
    return "";
}

std::string rosNamespaceRefusal(const std::string &ns) {
    const std::string why = namespaceProblem(ns);
    if (why.empty()) return "";
    return "'" + sdk::printable(ns) + "': " + why + "; ROS 2 expects '/' followed by names of letters, digits and '_' "
           "that do not start with a digit, joined by single '/' (e.g. /vehicle/stereo)";
}

void checkRosbagOptions(const RosbagOptions &o) {
    if (const std::string why = rosNamespaceRefusal(o.ros_namespace); !why.empty()) throw Error("--ros-namespace " + why);
    for (const auto *f : {&o.frame_id_left, &o.frame_id_right, &o.frame_id_ground})
        if (!rosName(*f, true))
            throw Error("frame id '" + sdk::printable(*f) + "': expected letters, digits, '_' and '/' (e.g. stereo_left_optical)");
}

RosbagWriter::RosbagWriter(const std::string &dir, const std::optional<StereoCalibration> &calibration,
                           const RosbagOptions &options)
    : dir_(dir), options_(options), calibration_(calibration) {
    checkRosbagOptions(options_);
    std::error_code ec;
    // The lock and marker of `binocle record`/`run` (core/output_folder.hpp) are not content.
    if (fs::exists(dir, ec) && (!fs::is_directory(dir, ec) || !entriesOf(dir).empty()))
        throw Error("rosbag: '" + dir + "' exists and is not an empty folder; a bag is never written over anything");
    fs::create_directories(dir, ec);
    if (ec) throw Error("rosbag: cannot create folder '" + dir + "': " + ec.message());
    std::string name = fs::path(dir).lexically_normal().filename().string();
    if (name.empty() || name == "." || name == "..") name = "binocle";
    file_ = (fs::path(dir) / (name + "_0.mcap")).string();
    mcap::WriterOptions w;
    w.library = "binocle";
    w.compression = options_.compression;
    w.compression_level = options_.compression_level;
    try {
        writer_ = std::make_unique<mcap::Writer>(file_, w);
    } catch (const mcap::Error &e) {
        throw Error(e.what());
    }
    if (calibration_ && calibration_->P1.empty()) calibration_->computeRectification();
    writeMetadataYaml(); // readable at once; rewritten with the counts by close()
}

RosbagWriter::~RosbagWriter() {
    try {
        close();
    } catch (...) {
    }
}

uint16_t RosbagWriter::channel(const std::string &topic, const char *type) {
    auto it = channels_.find(topic);
    if (it != channels_.end()) return it->second.first;
    const uint16_t schema = writer_->addSchema(type, "ros2msg", ros2::definition(type));
    // rosbag2 stores each topic's QoS; readers (ros2 bag play) accept an empty list.
    const uint16_t id = writer_->addChannel(schema, topic, "cdr", {{"offered_qos_profiles", ""}});
    channels_[topic] = {id, type};
    return id;
}

void RosbagWriter::write(const std::string &topic, const char *type, int64_t stampNs, const std::vector<uint8_t> &bytes) {
    const uint16_t id = channel(topic, type);
    const auto t = static_cast<uint64_t>(std::max<int64_t>(stampNs, 0));
    try {
        writer_->write(id, sequence_++, t, t, bytes.data(), bytes.size());
    } catch (const mcap::Error &e) {
        throw Error(e.what());
    }
    ++counts_[topic];
    first_ = std::min(first_, stampNs);
    last_ = std::max(last_, stampNs);
}

void RosbagWriter::writePair(int64_t stampLeftNs, int64_t stampRightNs, const cv::Mat &left, const cv::Mat &right,
                             bool rgb, bool rectified) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) throw Error("rosbag: write after close");
    const std::string &ns = options_.ros_namespace == "/" ? std::string() : options_.ros_namespace;
    const char *kind = rectified ? "image_rect" : "image_raw";
    for (int side = 0; side < 2; ++side) {
        const cv::Mat m = (side ? right : left).isContinuous() ? (side ? right : left) : (side ? right : left).clone();
        const int64_t stamp = side ? stampRightNs : stampLeftNs;
        const std::string &frame = side ? options_.frame_id_right : options_.frame_id_left;
        const std::string sideNs = ns + (side ? "/right/" : "/left/");
        write(sideNs + kind, ros2::Image::kType, stamp, ros2::encode(imageMessage(m, encodingOf(m, rgb), stamp, frame)));
        if (!rectified && calibration_) {
            const StereoCalibration &c = *calibration_;
            ros2::StereoCameraModel model;
            model.width = static_cast<uint32_t>(c.image_size.width);
            model.height = static_cast<uint32_t>(c.image_size.height);
            model.M1 = arr9(c.M1);
            model.M2 = arr9(c.M2);
            model.D1.assign(c.D1.begin<double>(), c.D1.end<double>());
            model.D2.assign(c.D2.begin<double>(), c.D2.end<double>());
            model.R1 = arr9(c.R1);
            model.R2 = arr9(c.R2);
            for (int i = 0; i < 12; ++i) {
                model.P1[i] = c.P1.at<double>(i / 4, i % 4);
                model.P2[i] = c.P2.at<double>(i / 4, i % 4);
            }
            ros2::CameraInfo info = ros2::cameraInfos(model)[side];
            info.header.stamp = ros2::Time::fromNs(stamp);
            info.header.frame_id = frame;
            write(sideNs + "camera_info", ros2::CameraInfo::kType, stamp, ros2::encode(info));
        }
    }
    pairEnds_.push_back(writer_->statistics().message_count);
    countDurablePairs();
}

void RosbagWriter::countDurablePairs() {
    const uint64_t durable = writer_->durableMessageCount();
    int64_t pairs = durablePairs_.load();
    while (!pairEnds_.empty() && pairEnds_.front() <= durable) {
        pairEnds_.pop_front();
        ++pairs;
    }
    durablePairs_.store(pairs);
}

void RosbagWriter::writeDisparity(int64_t stampNs, const cv::Mat &disparity, double focalLengthPx, double baselineM,
                                  double minDisparity, double maxDisparity) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) throw Error("rosbag: write after close");
    cv::Mat d;
    disparity.convertTo(d, CV_32F);
    // ROS: a disparity below min_disparity is invalid; Binocle's invalid pixels (< 0, NaN)
    // become min_disparity - 1.
    const auto invalid = static_cast<float>(minDisparity - 1);
    for (int y = 0; y < d.rows; ++y) {
        auto *row = d.ptr<float>(y);
        for (int x = 0; x < d.cols; ++x)
            if (!std::isfinite(row[x]) || row[x] < 0) row[x] = invalid;
    }
    ros2::DisparityImage m;
    m.header.stamp = ros2::Time::fromNs(stampNs);
    m.header.frame_id = options_.frame_id_left;
    m.image = imageMessage(d, "32FC1", stampNs, options_.frame_id_left);
    m.f = static_cast<float>(focalLengthPx);
    m.t = static_cast<float>(baselineM);
    m.valid_window = {0, 0, static_cast<uint32_t>(d.rows), static_cast<uint32_t>(d.cols), false};
    m.min_disparity = static_cast<float>(minDisparity);
    m.max_disparity = static_cast<float>(maxDisparity);
    m.delta_d = 1.0f / 16; // the sub-pixel step of the OpenCV matchers
    const std::string ns = options_.ros_namespace == "/" ? std::string() : options_.ros_namespace;
    write(ns + "/disparity", ros2::DisparityImage::kType, stampNs, ros2::encode(m));
}

void RosbagWriter::writeCloud(int64_t stampNs, const std::vector<cv::Point3f> &points) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) throw Error("rosbag: write after close");
    ros2::PointCloud2 m;
    m.header.stamp = ros2::Time::fromNs(stampNs);
    m.header.frame_id = options_.frame_id_ground;
    m.height = 1;
    m.width = static_cast<uint32_t>(points.size());
    m.fields = {{"x", 0, ros2::PointField::FLOAT32, 1},
                {"y", 4, ros2::PointField::FLOAT32, 1},
                {"z", 8, ros2::PointField::FLOAT32, 1}};
    m.point_step = 12;
    m.row_step = 12 * m.width;
    m.data = reinterpret_cast<const uint8_t *>(points.data());
    m.size = points.size() * 12;
    m.is_dense = true;
    static_assert(sizeof(cv::Point3f) == 12, "x, y, z float32 packed");
    const std::string ns = options_.ros_namespace == "/" ? std::string() : options_.ros_namespace;
    write(ns + "/points", ros2::PointCloud2::kType, stampNs, ros2::encode(m));
}

void RosbagWriter::writeFigures(int64_t stampNs, const std::map<std::string, std::map<std::string, std::string>> &groups) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) throw Error("rosbag: write after close");
    ros2::DiagnosticArray a;
    a.header.stamp = ros2::Time::fromNs(stampNs);
    a.header.frame_id = options_.frame_id_left;
    for (const auto &[name, values] : groups) {
        ros2::DiagnosticStatus s;
        s.name = "binocle/" + name;
        s.hardware_id = options_.ros_namespace;
        s.values.assign(values.begin(), values.end());
        a.status.push_back(std::move(s));
    }
    const std::string ns = options_.ros_namespace == "/" ? std::string() : options_.ros_namespace;
    write(ns + "/figures", ros2::DiagnosticArray::kType, stampNs, ros2::encode(a));
}

void RosbagWriter::writeMetadataYaml() {
    // rosbag2's metadata.yaml (version 5: what Humble and later read).
    uint64_t total = 0;
    for (const auto &[t, n] : counts_) total += n;
    const int64_t start = counts_.empty() ? 0 : first_, duration = counts_.empty() ? 0 : last_ - first_;
    const std::string name = fs::path(file_).filename().string();
    std::ostringstream y;
    y << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n"
      << "  duration:\n    nanoseconds: " << duration << "\n"
      << "  starting_time:\n    nanoseconds_since_epoch: " << start << "\n"
      << "  message_count: " << total << "\n  topics_with_message_count:\n";
    if (channels_.empty()) y.seekp(-1, std::ios_base::cur), y << " []\n";
    for (const auto &[topic, c] : channels_)
        y << "    - topic_metadata:\n        name: " << topic << "\n        type: " << c.second
          << "\n        serialization_format: cdr\n        offered_qos_profiles: \"\"\n      message_count: "
          << counts_[topic] << "\n";
    y << "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - " << name << "\n"
      << "  files:\n    - path: " << name << "\n      starting_time:\n        nanoseconds_since_epoch: " << start
      << "\n      duration:\n        nanoseconds: " << duration << "\n      message_count: " << total << "\n";
    writeFileAtomic((fs::path(dir_) / "metadata.yaml").string(), y.str());
}

void RosbagWriter::close() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return;
    closed_ = true;
    try {
        writer_->close();
    } catch (const mcap::Error &e) {
        countDurablePairs(); // the chunks written before the failure still count
        throw Error(e.what());
    }
    countDurablePairs();
    writeMetadataYaml();
}

uint64_t RosbagWriter::messageCount() const { return writer_->statistics().message_count; }
uint64_t RosbagWriter::bytesWritten() const { return writer_->bytesWritten(); }

} // namespace binocle
