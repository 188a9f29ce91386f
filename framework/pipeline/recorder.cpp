// SPDX-License-Identifier: MIT
// Recording a rig's source to a folder in the `recording` layout of plugins/replay/README.md.
#include "pipeline/recorder.hpp"

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/progress.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;

namespace binocle {

namespace {

constexpr const char *kCsvHeader = "sequence,timestamp_left_ns,timestamp_right_ns,left,right\n";

// Writes all of `text` to `fd` and makes it durable; throws naming `path`.
void writeDurably(int fd, const std::string &text, const std::string &path) {
    size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw Error("cannot write " + path + ": " + std::strerror(errno));
        done += static_cast<size_t>(n);
    }
    if (::fsync(fd) != 0) throw Error("cannot write " + path + ": fsync failed: " + std::strerror(errno));
}

std::string listed(const fs::path &dir) {
    std::vector<std::string> names;
    for (const auto &e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    std::string out;
    for (size_t i = 0; i < names.size() && i < 4; ++i) out += (i ? ", " : "") + names[i];
    if (names.size() > 4) out += ", ... (" + std::to_string(names.size()) + " entries)";
    return out;
}

// A lent image as a cv::Mat view; RGB8 is flagged so that PNG gets the right colours.
cv::Mat view(const binocle_image &im, bool &rgb) {
    rgb = im.format == BINOCLE_PIXEL_RGB8;
    int type = 0;
    switch (im.format) {
    case BINOCLE_PIXEL_GRAY8: type = CV_8UC1; break;
    case BINOCLE_PIXEL_BGR8:
    case BINOCLE_PIXEL_RGB8: type = CV_8UC3; break;
    case BINOCLE_PIXEL_GRAY16: type = CV_16UC1; break;
    default: throw Error("record: images of format " + std::to_string(im.format) + " cannot be recorded (GRAY8, GRAY16, BGR8 or RGB8)");
    }
    return cv::Mat(im.height, im.width, type, im.data, static_cast<size_t>(im.stride_bytes));
}

} // namespace

std::string RecordingWriter::imagePath(const std::string &side, uint64_t sequence) {
    char name[32];
    std::snprintf(name, sizeof name, "%06llu.png", static_cast<unsigned long long>(sequence));
    return side + "/" + name;
}

RecordingWriter::RecordingWriter(const std::string &dir, const std::string &calibrationYaml, const std::string &rigYaml)
    : dir_(dir) {
    std::error_code ec;
    if (fs::exists(dir_, ec)) {
        if (!fs::is_directory(dir_, ec)) throw Error("record: " + dir_ + " exists and is not a folder");
        if (!fs::is_empty(dir_, ec))
            throw Error("record: " + dir_ + " is not empty (it holds " + listed(dir_) +
                        "): refusing to record over it; choose a new folder");
    }
    fs::create_directories(fs::path(dir_) / "left", ec);
    if (!ec) fs::create_directories(fs::path(dir_) / "right", ec);
    if (ec) throw Error("record: cannot create " + dir_ + ": " + ec.message());
    if (!calibrationYaml.empty()) writeFileAtomic((fs::path(dir_) / "calibration.yml").string(), calibrationYaml);
    if (!rigYaml.empty()) writeFileAtomic((fs::path(dir_) / "rig.yaml").string(), rigYaml);
    const std::string csv = (fs::path(dir_) / "frames.csv").string();
    // O_EXCL: even a recorder racing for the same folder cannot truncate another's index.
    csvFd_ = ::open(csv.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_APPEND | O_CLOEXEC, 0644);
    if (csvFd_ < 0) throw Error("record: cannot create " + csv + ": " + std::strerror(errno));
    writeDurably(csvFd_, kCsvHeader, csv);
}

RecordingWriter::~RecordingWriter() {
    if (csvFd_ >= 0) ::close(csvFd_);
}

void RecordingWriter::append(uint64_t sequence, int64_t timestampLeftNs, int64_t timestampRightNs, const cv::Mat &left,
                             const cv::Mat &right, bool rgb) {
    const std::string paths[2] = {imagePath("left", sequence), imagePath("right", sequence)};
    const cv::Mat *images[2] = {&left, &right};
    for (int i = 0; i < 2; ++i) {
        const std::string file = (fs::path(dir_) / paths[i]).string();
        cv::Mat toWrite = *images[i];
        if (rgb && toWrite.channels() == 3) cv::cvtColor(toWrite, toWrite, cv::COLOR_RGB2BGR);
        std::vector<uchar> png;
        try {
            // Level 1: lossless all the same, several times faster than the default.
            if (!cv::imencode(".png", toWrite, png, {cv::IMWRITE_PNG_COMPRESSION, 1})) throw Error("cannot encode " + file);
        } catch (const cv::Exception &e) {
            throw Error("record: cannot encode " + file + ": " + e.err);
        }
        // Temporary file, fsync, rename: the image is complete on disk before its line.
        writeFileAtomic(file, std::string(png.begin(), png.end()));
    }
    const std::string line = std::to_string(sequence) + "," + std::to_string(timestampLeftNs) + "," +
                             std::to_string(timestampRightNs) + "," + paths[0] + "," + paths[1] + "\n";
    writeDurably(csvFd_, line, (fs::path(dir_) / "frames.csv").string());
    ++frames_;
}

void RecordingWriter::append(const LentFrame &frame) {
    const binocle_stereo_frame &f = frame.raw();
    bool rgbLeft = false, rgbRight = false;
    const cv::Mat left = view(f.left, rgbLeft), right = view(f.right, rgbRight);
    append(f.sequence, f.timestamp_left_ns, f.timestamp_right_ns, left, right, rgbLeft || rgbRight);
}

RecordResult recordRig(const RigConfig &rig, const std::string &dir, const RecordOptions &options,
                       const std::function<void(int64_t frames)> &onFrame) {
    Source source(*rig.source.record, rig.source.params);
    std::string calibration;
    if (rig.calibration_file) calibration = readTextFile(*rig.calibration_file);
    else calibration = source.calibration();
    RecordingWriter writer(dir, calibration, rig.resolved_yaml);

    RecordResult result;
    const auto begin = std::chrono::steady_clock::now();
    Progress progress(options.progress, "frame", options.max_frames);
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count(); };
    try {
        source.start();
        while (options.max_frames < 0 || writer.frameCount() < options.max_frames) {
            if (options.stop && options.stop->load()) break;
            std::unique_ptr<LentFrame> frame = source.grab(options.grab_timeout_ms);
            if (!frame) break;
            writer.append(*frame);
            frame.reset(); // give the buffer back before waiting for the next one
            if (onFrame) onFrame(writer.frameCount());
            progress.update(writer.frameCount(), "recorded");
        }
        source.stop();
    } catch (const std::exception &e) {
        result.error = e.what();
    }
    progress.finish();
    try {
        result.source_statistics = source.statistics();
    } catch (const std::exception &) {
    }
    result.frames = writer.frameCount();
    result.seconds = elapsed();
    return result;
}

} // namespace binocle
