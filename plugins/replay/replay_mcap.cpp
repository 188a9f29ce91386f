// SPDX-License-Identifier: MIT
// replay's `mcap` layout: a rosbag2 MCAP bag read with Binocle::mcap (see replay_mcap.hpp).
#include "replay_mcap.hpp"

#include "input/image_file.hpp"

#include <binocle/text.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <sys/stat.h>

namespace fs = std::filesystem;

namespace binocle::replay {

using sdk::Error;

namespace {

constexpr uint64_t kMaxMetadataYamlBytes = uint64_t{1} << 20;

std::string quoteText(const std::string &s) { return "'" + sdk::printable(s, 200) + "'"; }

[[noreturn]] void refuse(binocle_result code, const std::string &what) { throw Error(code, "replay: " + what); }

// OpenCV's Bayer names count from the second row: ROS bayer_rggb is OpenCV's BayerBG
// (the mapping cv_bridge uses).
int bayerCode(const std::string &encoding, bool gray) {
    const std::string p = encoding.substr(6, 4);
    if (p == "rggb") return gray ? cv::COLOR_BayerBG2GRAY : cv::COLOR_BayerBG2BGR;
    if (p == "bggr") return gray ? cv::COLOR_BayerRG2GRAY : cv::COLOR_BayerRG2BGR;
    if (p == "gbrg") return gray ? cv::COLOR_BayerGR2GRAY : cv::COLOR_BayerGR2BGR;
    if (p == "grbg") return gray ? cv::COLOR_BayerGB2GRAY : cv::COLOR_BayerGB2BGR;
    return -1;
}

bool isImageType(const std::string &name) { return name == ros2::Image::kType || name == "sensor_msgs/Image"; }
bool isCompressedType(const std::string &name) {
    return name == ros2::CompressedImage::kType || name == "sensor_msgs/CompressedImage";
}

} // namespace

cv::Mat imageToMat(const ros2::Image &image, bool gray, const std::string &where) {
    // The encodings read below, named in the refusal (the SDK's layout check knows more:
    // 32FC1 and 16UC3 are images, but not a camera's).
    static const char *const kCameraEncodings[] = {"mono8",  "mono16", "8UC1",  "16UC1", "rgb8", "bgr8",
                                                   "8UC3",   "rgba8",  "bgra8", "8UC4"};
    const bool known = std::find_if(std::begin(kCameraEncodings), std::end(kCameraEncodings),
                                    [&](const char *e) { return image.encoding == e; }) != std::end(kCameraEncodings) ||
                       (image.encoding.rfind("bayer_", 0) == 0 && ros2::Image::bytesPerPixel(image.encoding) > 0);
    if (!known)
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, where + ": encoding " + quoteText(image.encoding) +
                                                 " is not a camera image encoding replay reads; expected mono8, mono16, "
                                                 "rgb8, bgr8, rgba8, bgra8, 8UC1, 16UC1, 8UC3, 8UC4 or bayer_<pattern>8/16 "
                                                 "(e.g. bayer_rggb8)");
    try {
        image.checkLayout(where);
    } catch (const ros2::Error &e) {
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, e.what());
    }
    const std::string &e = image.encoding;
    if (image.width > input::kMaxImageSide || image.height > input::kMaxImageSide ||
        int64_t{image.width} * image.height > input::kMaxImagePixels)
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, where + ": image of " + std::to_string(image.width) + "x" +
                                                 std::to_string(image.height) + " pixels; at most " +
                                                 std::to_string(input::kMaxImageSide) + " a side and " +
                                                 std::to_string(input::kMaxImagePixels) + " in all");
    const int bpp = ros2::Image::bytesPerPixel(e);
    const bool bayer = e.rfind("bayer_", 0) == 0;
    const bool sixteen = e == "mono16" || e == "16UC1" || (bayer && bpp == 2);
    int type = CV_8UC1;
    if (sixteen) type = CV_16UC1;
    else if (bpp == 3) type = CV_8UC3;
    else if (bpp == 4 && e != "32FC1") type = CV_8UC4;
    // A view of the message's bytes (rows `step` apart); converted below into owned pixels.
    // A step that is not a whole number of samples (mono16 with an odd step: legal in ROS)
    // cannot be viewed by OpenCV: the rows are copied together first.
    cv::Mat view;
    if (image.step % CV_ELEM_SIZE1(type) == 0) {
        view = cv::Mat(static_cast<int>(image.height), static_cast<int>(image.width), type, const_cast<uint8_t *>(image.data),
                       image.step);
    } else {
        view.create(static_cast<int>(image.height), static_cast<int>(image.width), type);
        const size_t rowBytes = view.cols * view.elemSize();
        for (int y = 0; y < view.rows; ++y) std::memcpy(view.ptr(y), image.data + size_t{image.step} * y, rowBytes);
    }
    cv::Mat m;
    if (sixteen) {
        cv::Mat v = view;
        if (image.is_bigendian) {
            v = view.clone();
            for (int y = 0; y < v.rows; ++y) {
                auto *row = v.ptr<uint16_t>(y);
                for (int x = 0; x < v.cols; ++x) row[x] = static_cast<uint16_t>((row[x] >> 8) | (row[x] << 8));
            }
        }
        if (bayer) {
            const int code = bayerCode(e, gray);
            if (code < 0) refuse(BINOCLE_ERR_INVALID_ARGUMENT, where + ": unknown Bayer pattern in encoding " + e);
            cv::Mat demosaiced;
            cv::cvtColor(v, demosaiced, code);
            demosaiced.convertTo(m, gray ? CV_8UC1 : CV_8UC3, 1.0 / 256);
            return m;
        }
        v.convertTo(m, CV_8UC1, 1.0 / 256);
        if (!gray) cv::cvtColor(m, m, cv::COLOR_GRAY2BGR);
        return m;
    }
    if (bayer) {
        const int code = bayerCode(e, gray);
        if (code < 0) refuse(BINOCLE_ERR_INVALID_ARGUMENT, where + ": unknown Bayer pattern in encoding " + e);
        cv::cvtColor(view, m, code);
        return m;
    }
    if (type == CV_8UC1) {
        if (gray) return view.clone();
        cv::cvtColor(view, m, cv::COLOR_GRAY2BGR);
        return m;
    }
    const bool rgb = e == "rgb8" || e == "rgba8";
    if (type == CV_8UC3) {
        if (gray) cv::cvtColor(view, m, rgb ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
        else if (rgb) cv::cvtColor(view, m, cv::COLOR_RGB2BGR);
        else m = view.clone();
        return m;
    }
    cv::cvtColor(view, m, gray ? (rgb ? cv::COLOR_RGBA2GRAY : cv::COLOR_BGRA2GRAY) : (rgb ? cv::COLOR_RGBA2BGR : cv::COLOR_BGRA2BGR));
    return m;
}

cv::Mat compressedToMat(const ros2::CompressedImage &image, bool gray, const std::string &where) {
    // "jpeg", "png", or image_transport's "bgr8; jpeg compressed bgr8".
    const std::string f = image.format;
    if (f.find("jpeg") == std::string::npos && f.find("jpg") == std::string::npos && f.find("png") == std::string::npos)
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, where + ": CompressedImage format " + quoteText(f) + "; expected jpeg or png");
    const int flags = (gray ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR) | cv::IMREAD_IGNORE_ORIENTATION;
    try {
        cv::Mat m = input::decodeImage(image.data, image.size, flags, where);
        if (m.depth() != CV_8U) m.convertTo(m, CV_8U, 1.0 / 256);
        return m;
    } catch (const input::ImageFileError &e) {
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, e.what());
    }
}

bool isMcapBag(const std::string &path) {
    std::error_code ec;
    if (fs::is_regular_file(path, ec)) return fs::path(path).extension() == ".mcap";
    if (!fs::is_directory(path, ec)) return false;
    if (fs::is_regular_file(fs::path(path) / "metadata.yaml", ec)) return true;
    for (const auto &entry : fs::directory_iterator(path, ec))
        if (entry.path().extension() == ".mcap" && entry.is_regular_file(ec)) return true;
    return false;
}

// ---- Opening -----------------------------------------------------------------------------

void McapPairs::openFiles(const std::string &bag) {
    std::error_code ec;
    std::vector<fs::path> files;
    if (fs::is_directory(bag, ec)) {
        const fs::path meta = fs::path(bag) / "metadata.yaml";
        if (fs::is_regular_file(meta, ec)) {
            if (fs::file_size(meta, ec) > kMaxMetadataYamlBytes)
                refuse(BINOCLE_ERR_INVALID_ARGUMENT, "rosbag2 metadata " + quoteText(meta.string()) + " holds more than " +
                                                         std::to_string(kMaxMetadataYamlBytes) + " bytes");
            YAML::Node info;
            try {
                info = YAML::LoadFile(meta.string())["rosbag2_bagfile_information"];
            } catch (const YAML::Exception &e) {
                refuse(BINOCLE_ERR_INVALID_ARGUMENT, "rosbag2 metadata " + quoteText(meta.string()) + ": " + e.what());
            }
            if (!info || !info["relative_file_paths"] || !info["relative_file_paths"].IsSequence())
                refuse(BINOCLE_ERR_INVALID_ARGUMENT, "rosbag2 metadata " + quoteText(meta.string()) +
                                                         " has no rosbag2_bagfile_information.relative_file_paths list");
            if (info["storage_identifier"] && info["storage_identifier"].as<std::string>("") != "mcap")
                refuse(BINOCLE_ERR_INVALID_ARGUMENT, "rosbag2 metadata " + quoteText(meta.string()) + ": storage_identifier " +
                                                         quoteText(info["storage_identifier"].as<std::string>("")) +
                                                         "; expected mcap (sqlite3 bags are not read)");
            for (const YAML::Node &p : info["relative_file_paths"]) {
                const std::string rel = p.as<std::string>("");
                std::string why;
                if (!sdk::isConfinedRelativePath(rel, &why))
                    refuse(BINOCLE_ERR_INVALID_ARGUMENT, "rosbag2 metadata " + quoteText(meta.string()) + " names file " +
                                                             quoteText(rel) + ": " + why);
                // rosbag2 writes either "x_0.mcap" or "bagname/x_0.mcap".
                fs::path f = fs::path(bag) / rel;
                if (!fs::exists(f, ec)) f = fs::path(bag) / fs::path(rel).filename();
                f = f.lexically_normal();
                // Each file once: a file listed twice would play every pair twice.
                if (std::find(files.begin(), files.end(), f) != files.end())
                    refuse(BINOCLE_ERR_INVALID_ARGUMENT, "rosbag2 metadata " + quoteText(meta.string()) + " names file " +
                                                             quoteText(rel) + " twice (as " + quoteText(f.string()) +
                                                             "); expected each file of the bag once");
                files.push_back(f);
            }
        } else {
            for (const auto &entry : fs::directory_iterator(bag, ec))
                if (entry.path().extension() == ".mcap") files.push_back(entry.path());
            std::sort(files.begin(), files.end());
        }
        if (files.empty())
            refuse(BINOCLE_ERR_NOT_FOUND, "bag folder " + quoteText(bag) + " holds no .mcap file (and no metadata.yaml naming one)");
    } else if (fs::is_regular_file(bag, ec)) {
        files.emplace_back(bag);
    } else if (struct stat st {}; ::stat(bag.c_str(), &st) == 0) {
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, "bag " + quoteText(bag) + " is " + sdk::fileTypeName(st.st_mode) +
                                                 "; expected an .mcap file or a rosbag2 folder");
    } else {
        refuse(BINOCLE_ERR_NOT_FOUND, "bag " + quoteText(bag) + " does not exist; expected an .mcap file or a rosbag2 folder");
    }
    for (const fs::path &f : files) {
        // Never opened unless a regular file: a FIFO would block the open for ever, a
        // device (/dev/zero) never ends. mcap::Reader refuses them too, without blocking.
        if (struct stat st {}; ::stat(f.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
            refuse(BINOCLE_ERR_INVALID_ARGUMENT, "bag file " + quoteText(f.string()) + " is " + sdk::fileTypeName(st.st_mode) +
                                                     "; expected a regular .mcap file");
        try {
            readers_.push_back(std::make_unique<mcap::Reader>(f.string()));
        } catch (const mcap::Error &e) {
            refuse(BINOCLE_ERR_INVALID_ARGUMENT, e.what());
        }
        fileList_ += (fileList_.empty() ? "" : ", ") + f.string();
    }
}

std::string McapPairs::topicList() const {
    std::map<std::string, std::pair<std::string, uint64_t>> topics;
    for (const auto &r : readers_)
        for (const auto &[id, ch] : r->channels()) {
            const mcap::Schema *s = r->schemaOf(ch);
            auto &t = topics[ch.topic];
            t.first = s ? s->name : "no schema";
            auto it = r->statistics().channel_message_counts.find(id);
            if (it != r->statistics().channel_message_counts.end()) t.second += it->second;
        }
    std::string out;
    for (const auto &[topic, t] : topics)
        out += (out.empty() ? "" : ", ") + sdk::printable(topic) + " (" + sdk::printable(t.first) + ", " +
               std::to_string(t.second) + " messages)";
    return out.empty() ? "no topics" : out;
}

void McapPairs::pickTopics(const McapSettings &s) {
    std::vector<std::string> images; // topics of Image or CompressedImage messages
    for (const auto &r : readers_)
        for (const auto &[id, ch] : r->channels()) {
            const mcap::Schema *schema = r->schemaOf(ch);
            if (schema && (isImageType(schema->name) || isCompressedType(schema->name)) &&
                std::find(images.begin(), images.end(), ch.topic) == images.end())
                images.push_back(ch.topic);
        }
    auto has = [&](const std::string &t) { return std::find(images.begin(), images.end(), t) != images.end(); };
    if (!s.leftTopic.empty() || !s.rightTopic.empty()) {
        if (s.leftTopic.empty() || s.rightTopic.empty())
            refuse(BINOCLE_ERR_INVALID_ARGUMENT, "left_topic " + quoteText(s.leftTopic) + " and right_topic " +
                                                     quoteText(s.rightTopic) + ": set both, or neither to find the pair");
        for (const std::string *t : {&s.leftTopic, &s.rightTopic})
            if (!has(*t))
                refuse(BINOCLE_ERR_NOT_FOUND, "bag " + fileList_ + " has no image topic " + quoteText(*t) +
                                                  "; its topics: " + topicList());
        topics_[0] = s.leftTopic;
        topics_[1] = s.rightTopic;
        return;
    }
    // `.../left/X` with `.../right/X`; image_raw preferred when there are several.
    std::vector<std::pair<std::string, std::string>> found;
    for (const std::string &t : images) {
        const size_t at = t.rfind("left/");
        if (at == std::string::npos || (at > 0 && t[at - 1] != '/')) continue;
        const std::string right = t.substr(0, at) + "right/" + t.substr(at + 5);
        if (has(right)) found.emplace_back(t, right);
    }
    if (found.size() > 1) {
        std::vector<std::pair<std::string, std::string>> raw;
        for (const auto &p : found)
            if (p.first.size() >= 9 && p.first.compare(p.first.size() - 9, 9, "image_raw") == 0) raw.push_back(p);
        if (raw.size() == 1) found = raw;
    }
    if (found.size() != 1) {
        std::string pairs;
        for (const auto &p : found) pairs += (pairs.empty() ? "" : ", ") + sdk::printable(p.first) + " + " + sdk::printable(p.second);
        refuse(BINOCLE_ERR_NOT_FOUND, "bag " + fileList_ + ": " +
                                          (found.empty() ? std::string("no pair of image topics named */left/X and */right/X")
                                                         : "several pairs of image topics (" + pairs + ")") +
                                          "; set left_topic and right_topic. Its topics: " + topicList());
    }
    topics_[0] = found[0].first;
    topics_[1] = found[0].second;
}

// ---- Index and pairs -------------------------------------------------------------------------

std::string McapPairs::where(const Message &m, int side) const {
    const mcap::Reader &r = *readers_[m.file];
    std::string w = r.path() + ": topic " + sdk::printable(topics_[side]) + ", message at offset ";
    if (m.chunk == SIZE_MAX) return w + std::to_string(m.recordOffset);
    return w + std::to_string(m.recordOffset) + " of the chunk at offset " + std::to_string(r.chunks()[m.chunk].offset);
}

void McapPairs::index(const McapSettings &s) {
    uint64_t first = UINT64_MAX;
    for (const auto &r : readers_)
        if (r->statistics().message_count > 0) first = std::min(first, r->statistics().message_start_time);
    if (first == UINT64_MAX) refuse(BINOCLE_ERR_NOT_FOUND, "bag " + fileList_ + " holds no message");
    const uint64_t start = first + static_cast<uint64_t>(std::llround(s.startS * 1e9));
    const uint64_t end = s.durationS > 0 ? start + static_cast<uint64_t>(std::llround(s.durationS * 1e9)) : UINT64_MAX;
    for (size_t f = 0; f < readers_.size(); ++f) {
        const mcap::Reader &r = *readers_[f];
        std::map<int64_t, size_t> chunkByOffset;
        for (size_t i = 0; i < r.chunks().size(); ++i) chunkByOffset[static_cast<int64_t>(r.chunks()[i].offset)] = i;
        std::vector<uint16_t> ids;
        std::map<uint16_t, std::pair<int, bool>> sideOf; // side, compressed
        for (int side = 0; side < 2; ++side) {
            const mcap::Channel *ch = r.channelByTopic(topics_[side]);
            if (!ch) continue;
            const mcap::Schema *schema = r.schemaOf(*ch);
            if (ch->message_encoding != "cdr")
                refuse(BINOCLE_ERR_INVALID_ARGUMENT, r.path() + ": topic " + quoteText(topics_[side]) + " has message encoding " +
                                                         quoteText(ch->message_encoding) + "; expected cdr (ROS 2)");
            const std::string type = schema ? schema->name : "";
            if (!isImageType(type) && !isCompressedType(type))
                refuse(BINOCLE_ERR_INVALID_ARGUMENT, r.path() + ": topic " + quoteText(topics_[side]) + " carries " +
                                                         quoteText(type) + "; expected sensor_msgs/msg/Image or CompressedImage");
            ids.push_back(ch->id);
            sideOf[ch->id] = {side, isCompressedType(type)};
        }
        try {
            r.readMessages(
                [&](const mcap::MessageView &v) {
                    Message m;
                    m.file = f;
                    m.chunk = v.chunk_offset < 0 ? SIZE_MAX : chunkByOffset.at(v.chunk_offset);
                    m.recordOffset = v.record_offset;
                    m.logTimeNs = v.log_time;
                    const auto [side, compressed] = sideOf.at(v.channel->id);
                    m.compressed = compressed;
                    try {
                        m.stampNs = ros2::decodeHeader(v.data, v.size, compressed ? ros2::CompressedImage::kType
                                                                                  : ros2::Image::kType)
                                        .stamp.ns();
                    } catch (const ros2::Error &e) {
                        refuse(BINOCLE_ERR_INVALID_ARGUMENT, where(m, side) + ": " + e.what());
                    }
                    messages_.push_back(m);
                    (side == 0 ? leftIds_ : rightIds_).push_back(messages_.size() - 1);
                    return true;
                },
                ids, start, end);
        } catch (const mcap::Error &e) {
            refuse(BINOCLE_ERR_INVALID_ARGUMENT, e.what());
        }
    }
}

void McapPairs::pair(const McapSettings &s) {
    auto byStamp = [&](size_t a, size_t b) { return messages_[a].stampNs < messages_[b].stampNs; };
    std::stable_sort(leftIds_.begin(), leftIds_.end(), byStamp);
    std::stable_sort(rightIds_.begin(), rightIds_.end(), byStamp);
    const auto tol = static_cast<int64_t>(std::llround(s.pairToleranceMs * 1e6));
    size_t i = 0, j = 0;
    while (i < leftIds_.size() && j < rightIds_.size()) {
        const Message &l = messages_[leftIds_[i]], &r = messages_[rightIds_[j]];
        if (std::llabs(l.stampNs - r.stampNs) <= tol) {
            pairs_.push_back({l.stampNs, r.stampNs, std::min(l.logTimeNs, r.logTimeNs), leftIds_[i], rightIds_[j]});
            ++i;
            ++j;
        } else if (l.stampNs < r.stampNs) {
            ++unpaired_[0];
            ++i;
        } else {
            ++unpaired_[1];
            ++j;
        }
    }
    unpaired_[0] += leftIds_.size() - i;
    unpaired_[1] += rightIds_.size() - j;
}

McapPairs::McapPairs(const McapSettings &s, const sdk::Host &host) {
    if (!(s.pairToleranceMs >= 0) || !std::isfinite(s.pairToleranceMs))
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, "pair_tolerance_ms " + std::to_string(s.pairToleranceMs) + ": expected >= 0");
    if (!(s.startS >= 0) || !(s.durationS >= 0) || !std::isfinite(s.startS) || !std::isfinite(s.durationS) ||
        s.startS > 1e9 || s.durationS > 1e9)
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, "start_s " + std::to_string(s.startS) + ", duration_s " +
                                                 std::to_string(s.durationS) + ": expected seconds >= 0 (duration 0 = to the end)");
    openFiles(s.bag);
    for (const auto &r : readers_)
        if (!r->recoveryNote().empty()) host.warning("replay: " + r->path() + ": " + r->recoveryNote());
    pickTopics(s);
    index(s);
    pair(s);
    if (pairs_.empty())
        refuse(BINOCLE_ERR_NOT_FOUND, "bag " + fileList_ + ": no pair of " + topics_[0] + " and " + topics_[1] +
                                          " within pair_tolerance_ms " + std::to_string(s.pairToleranceMs) + " (" +
                                          std::to_string(leftIds_.size()) + " left and " + std::to_string(rightIds_.size()) +
                                          " right images in the time window)");
    if (unpaired_[0] + unpaired_[1] > 0)
        host.warning("replay: bag " + fileList_ + ": " + std::to_string(unpaired_[0]) + " left and " +
                     std::to_string(unpaired_[1]) + " right image(s) without a partner within pair_tolerance_ms " +
                     std::to_string(s.pairToleranceMs) + " are left out");
}

cv::Mat McapPairs::decodeOne(const Message &m, int side, bool gray) const {
    const mcap::Reader &r = *readers_[m.file];
    const std::string w = where(m, side);
    try {
        std::shared_ptr<const std::vector<uint8_t>> hold;
        const mcap::MessageView v = r.messageAt(m.chunk, m.recordOffset, hold);
        if (m.compressed) return compressedToMat(ros2::decodeCompressedImage(v.data, v.size), gray, w);
        return imageToMat(ros2::decodeImage(v.data, v.size), gray, w);
    } catch (const mcap::Error &e) {
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, e.what());
    } catch (const ros2::Error &e) {
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, w + ": " + e.what());
    }
}

void McapPairs::decode(size_t i, bool gray, cv::Mat &left, cv::Mat &right) const {
    const Pair &p = pairs_.at(i);
    left = decodeOne(messages_[p.left], 0, gray);
    right = decodeOne(messages_[p.right], 1, gray);
}

// ---- Calibration ---------------------------------------------------------------------------

std::string McapPairs::calibrationYaml(std::string &why) const {
    ros2::CameraInfo info[2];
    bool found[2] = {false, false};
    std::string infoTopic[2];
    for (int side = 0; side < 2; ++side) {
        const std::string &t = topics_[side];
        // <ns>/left/image_raw -> <ns>/left/camera_info; .../image_raw/compressed too.
        std::string base = t;
        if (base.size() > 11 && base.compare(base.size() - 11, 11, "/compressed") == 0) base.resize(base.size() - 11);
        infoTopic[side] = base.substr(0, base.rfind('/') + 1) + "camera_info";
        for (const auto &r : readers_) {
            const mcap::Channel *ch = r->channelByTopic(infoTopic[side]);
            if (!ch || found[side]) continue;
            try {
                r->readMessages(
                    [&](const mcap::MessageView &v) {
                        info[side] = ros2::decodeCameraInfo(v.data, v.size);
                        found[side] = true;
                        return false;
                    },
                    {ch->id});
            } catch (const std::exception &e) {
                refuse(BINOCLE_ERR_INVALID_ARGUMENT, r->path() + ": topic " + quoteText(infoTopic[side]) + ": " + e.what());
            }
        }
    }
    if (!found[0] || !found[1]) {
        why = "the bag has no CameraInfo on " + infoTopic[found[0] ? 1 : 0];
        return {};
    }
    ros2::StereoCameraModel m;
    try {
        m = ros2::stereoModel(info[0], info[1], "bag " + fileList_ + " (" + infoTopic[0] + ", " + infoTopic[1] + ")");
    } catch (const ros2::Error &e) {
        refuse(BINOCLE_ERR_INVALID_ARGUMENT, e.what());
    }
    auto mat = [](const double *v, int rows, int cols) { return cv::Mat(rows, cols, CV_64F, const_cast<double *>(v)).clone(); };
    bool rectified = true;
    for (double d : m.D1) rectified = rectified && d == 0;
    for (double d : m.D2) rectified = rectified && d == 0;
    for (int i = 0; i < 9; ++i) rectified = rectified && m.R1[i] == (i % 4 == 0 ? 1 : 0) && m.R2[i] == m.R1[i];
    cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    fs << "image_width" << static_cast<int>(m.width) << "image_height" << static_cast<int>(m.height);
    // Rectified images: the projection is the camera (ROS: K of image_rect is P's left 3x3).
    fs << "M1" << (rectified ? mat(m.P1.data(), 3, 4).colRange(0, 3).clone() : mat(m.M1.data(), 3, 3));
    fs << "D1" << (m.D1.empty() ? cv::Mat::zeros(1, 5, CV_64F) : mat(m.D1.data(), 1, static_cast<int>(m.D1.size())));
    fs << "M2" << (rectified ? mat(m.P2.data(), 3, 4).colRange(0, 3).clone() : mat(m.M2.data(), 3, 3));
    fs << "D2" << (m.D2.empty() ? cv::Mat::zeros(1, 5, CV_64F) : mat(m.D2.data(), 1, static_cast<int>(m.D2.size())));
    fs << "R" << mat(m.R.data(), 3, 3) << "T" << mat(m.T.data(), 3, 1);
    fs << "rectified" << (rectified ? 1 : 0);
    // Named in every refusal of this calibration (core/calibration.hpp), beside its keys.
    fs << "source" << ("bag " + sdk::printable(fileList_, 200) + ", CameraInfo topics " + sdk::printable(infoTopic[0]) + " and " +
                       sdk::printable(infoTopic[1]));
    return fs.releaseAndGetString();
}

} // namespace binocle::replay
