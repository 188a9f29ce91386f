// SPDX-License-Identifier: MIT
// Fuzz harness: Binocle::mcap's reader (footer, summary, chunk indexes, the scan of a file
// without them, zstd/lz4 chunks, CRCs) and the ROS 2 decoders behind replay's mcap layout
// (Image -> pixels, CompressedImage, CameraInfo -> stereo model). The input is the file,
// handed to the reader through a memfd (no disk). Caps are lowered so that a lying size
// can never allocate more than the harness's memory limit.
#include "replay_mcap.hpp"

#include <binocle/mcap.hpp>
#include <binocle/ros2_messages.hpp>

#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <string>

namespace {

void decode(const binocle::mcap::Reader &r, const binocle::mcap::MessageView &m) {
    const binocle::mcap::Schema *s = r.schemaOf(*m.channel);
    if (!s) return;
    using namespace binocle;
    try {
        if (s->name == ros2::Image::kType) {
            const ros2::Image img = ros2::decodeImage(m.data, m.size);
            const cv::Mat px = replay::imageToMat(img, false, "fuzz");
            if (px.empty() || px.type() != CV_8UC3) std::abort();
        } else if (s->name == ros2::CompressedImage::kType) {
            replay::compressedToMat(ros2::decodeCompressedImage(m.data, m.size), true, "fuzz");
        } else if (s->name == ros2::CameraInfo::kType) {
            const ros2::CameraInfo ci = ros2::decodeCameraInfo(m.data, m.size);
            ros2::stereoModel(ci, ci, "fuzz");
        } else if (s->name == ros2::DisparityImage::kType) {
            ros2::decodeDisparityImage(m.data, m.size);
        } else if (s->name == ros2::PointCloud2::kType) {
            ros2::decodePointCloud2(m.data, m.size);
        }
    } catch (const ros2::Error &) {
    } catch (const sdk::Error &) {
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static const int fd = memfd_create("mcap_fuzz", MFD_CLOEXEC);
    if (fd < 0) std::abort();
    if (ftruncate(fd, 0) != 0 || pwrite(fd, data, size, 0) != static_cast<ssize_t>(size)) std::abort();
    binocle::mcap::ReaderOptions o;
    o.max_record_bytes = uint64_t{32} << 20;
    o.max_summary_bytes = uint64_t{8} << 20;
    try {
        binocle::mcap::Reader r("/proc/self/fd/" + std::to_string(fd), o);
        int n = 0;
        r.readMessages([&](const binocle::mcap::MessageView &m) {
            if (m.data + m.size < m.data) std::abort();
            decode(r, m);
            return ++n < 1000;
        });
    } catch (const binocle::mcap::Error &) {
    }
    return 0;
}
