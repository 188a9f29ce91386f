// SPDX-License-Identifier: MIT
// The folder a run writes: per-frame images and clouds, and frames.jsonl.
#include "pipeline/frame_writer.hpp"

#include "core/error.hpp"
#include "core/image_io.hpp"
#include "core/json.hpp"
#include "pipeline/pipeline.hpp"

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <unistd.h>

namespace fs = std::filesystem;

namespace binocle {

void writeFrameOutputs(const FrameResult &r, const OutputOptions &o, const std::string &dir) {
    char stem[32];
    std::snprintf(stem, sizeof stem, "%06llu", static_cast<unsigned long long>(r.sequence));
    const fs::path d(dir);
    if (o.disparity_png) writeDisparityPng16((d / ("disparity_" + std::string(stem) + ".png")).string(), r.disparity);
    if (o.disparity_color) writeImage((d / ("disparity_color_" + std::string(stem) + ".png")).string(), colorizeDisparity(r.disparity));
    if (o.disparity_pfm) writePfm((d / ("disparity_" + std::string(stem) + ".pfm")).string(), r.disparity);
    if (o.rectified_png) {
        writeImage((d / ("rectified_left_" + std::string(stem) + ".png")).string(), r.rectified_left);
        writeImage((d / ("rectified_right_" + std::string(stem) + ".png")).string(), r.rectified_right);
    }
    if (o.cloud_ply) writePly((d / ("cloud_" + std::string(stem) + ".ply")).string(), r.cloud);
}

namespace {

class FolderWriter : public FrameWriter {
public:
    FolderWriter(const std::string &dir, const OutputOptions &outputs)
        : dir_(dir), outputs_(outputs), path_((fs::path(dir) / "frames.jsonl").string()) {
        // O_NOFOLLOW: a symlink planted under the name is refused, never written through.
        fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd_ < 0) throw Error(path_ + ": cannot write: " + std::strerror(errno));
    }
    ~FolderWriter() override {
        if (fd_ >= 0) ::close(fd_);
    }

    void write(const FrameResult &r) override {
        const auto t0 = std::chrono::steady_clock::now();
        writeFrameOutputs(r, outputs_, dir_);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        Json line = Json::object();
        line["index"] = r.index;
        line["sequence"] = r.sequence;
        line["valid_pixel_ratio"] = r.valid_pixel_ratio;
        line["points"] = r.cloud.size();
        line["seconds"] = r.seconds + seconds;
        line["latency_s"] = r.latency_s;
        line["metrics"] = r.metrics;
        append(line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
    }

    void finish(Json &summary) override { summary["frames_file"] = "frames.jsonl"; }

private:
    // One write per line: a line is never interleaved with another; a short write (full
    // disk) is cut back so that the file ends with its last complete line.
    void append(const std::string &text) {
        const off_t before = ::lseek(fd_, 0, SEEK_END);
        size_t done = 0;
        while (done < text.size()) {
            const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                const int err = n < 0 ? errno : ENOSPC;
                if (before >= 0 && ::ftruncate(fd_, before) == 0) ::lseek(fd_, before, SEEK_SET);
                throw Error(path_ + ": cannot write: " + std::strerror(err));
            }
            done += static_cast<size_t>(n);
        }
    }

    std::string dir_;
    OutputOptions outputs_;
    std::string path_;
    int fd_ = -1;
};

} // namespace

std::unique_ptr<FrameWriter> makeFolderWriter(const std::string &dir, const OutputOptions &outputs) {
    return std::make_unique<FolderWriter>(dir, outputs);
}

} // namespace binocle
