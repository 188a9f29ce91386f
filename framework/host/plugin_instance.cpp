// SPDX-License-Identifier: MIT
// What every plugin instance has: its binocle_host and sink, the choice of where it runs,
// the error of a failed call, image checks and views (host/instance_support.hpp).
#include "host/plugin_instance.hpp"

#include "core/log.hpp"
#include "host/instance_support.hpp"

#include <sstream>
#include <spdlog/spdlog.h>

namespace binocle {

// ---- Instances ---------------------------------------------------------------------------------

namespace {

struct SinkContext {
    std::string plugin;
    HostSink sink;
};

void hostLog(void *ctx, int32_t level, const char *message) {
    try {
        auto *c = static_cast<SinkContext *>(ctx);
        std::string msg = message ? message : "";
        if (c->sink.log) return c->sink.log(level, msg);
        logFromPlugin(c->plugin, level, msg);
    } catch (...) {
    }
}

void hostMetric(void *ctx, const char *name, double value, const char *unit) {
    try {
        auto *c = static_cast<SinkContext *>(ctx);
        if (c->sink.metric) c->sink.metric(name ? name : "", value, unit ? unit : "");
    } catch (...) {
    }
}

void hostText(void *ctx, const char *name, const char *text) {
    try {
        auto *c = static_cast<SinkContext *>(ctx);
        if (c->sink.text) c->sink.text(name ? name : "", text ? text : "");
    } catch (...) {
    }
}

// One SinkContext per binocle_host; owned through the binocle_host's context pointer.
struct HostBlock {
    binocle_host host;
    SinkContext ctx;
};

// binocle_host is the first member: deleting through it deletes the block.
void deleteHostBlock(binocle_host *h) { delete reinterpret_cast<HostBlock *>(h); }

} // namespace

std::shared_ptr<binocle_host> defaultHost(const std::string &plugin) {
    auto block = new HostBlock{};
    block->ctx.plugin = plugin;
    block->host.struct_size = sizeof(binocle_host);
    block->host.context = &block->ctx;
    block->host.log = &hostLog;
    block->host.report_metric = &hostMetric;
    block->host.report_text = &hostText;
    return std::shared_ptr<binocle_host>(&block->host, deleteHostBlock);
}

PluginInstanceBase::PluginInstanceBase(const PluginRecord &record) : record_(record), host_(defaultHost(record.name)) {}

void PluginInstanceBase::setSink(HostSink sink) { reinterpret_cast<HostBlock *>(host_.get())->ctx.sink = std::move(sink); }

bool PluginInstanceBase::runsIsolated(const PluginRecord &record, const IsolationOptions &isolation) {
    return isolation.process || record.described;
}

void failCall(const PluginRecord &record, const std::string &what, int32_t code, const char *message) {
    std::string msg = std::string(kindName(record.kind)) + " plugin '" + record.name + "' (" + record.path + "): " + what +
                      " failed (" + resultName(code) + ")";
    if (message && *message) msg += ": " + std::string(message);
    throw PluginError(msg, code);
}

// Checks an image a plugin handed back; returns "" when fine, else what is wrong.
std::string checkImage(const binocle_image &im, const char *what) {
    std::ostringstream os;
    const int bpp = bytesPerPixel(im.format);
    if (bpp == 0) os << what << " has unknown pixel format " << im.format;
    else if (im.width <= 0 || im.height <= 0 || im.width > 65536 || im.height > 65536)
        os << what << " has an impossible size " << im.width << "x" << im.height;
    else if (static_cast<int64_t>(im.stride_bytes) < static_cast<int64_t>(im.width) * bpp)
        os << what << " has stride " << im.stride_bytes << " bytes, less than width " << im.width << " x " << bpp << " bytes";
    else if (!im.data)
        os << what << " has no pixel data (NULL)";
    return os.str();
}

namespace {

int cvType(int32_t format) {
    switch (format) {
    case BINOCLE_PIXEL_GRAY8: return CV_8UC1;
    case BINOCLE_PIXEL_GRAY16: return CV_16UC1;
    case BINOCLE_PIXEL_BGR8:
    case BINOCLE_PIXEL_RGB8: return CV_8UC3;
    case BINOCLE_PIXEL_FLOAT32: return CV_32FC1;
    default: return -1;
    }
}

} // namespace

cv::Mat view(const binocle_image &im) {
    return cv::Mat(im.height, im.width, cvType(im.format), im.data, static_cast<size_t>(im.stride_bytes));
}

binocle_image wrap(const cv::Mat &m, int32_t format) {
    binocle_image im{};
    im.width = m.cols;
    im.height = m.rows;
    im.stride_bytes = static_cast<int32_t>(m.step[0]);
    im.format = format;
    im.data = m.data;
    return im;
}

int32_t formatOf(const cv::Mat &m) {
    switch (m.type()) {
    case CV_8UC1: return BINOCLE_PIXEL_GRAY8;
    case CV_16UC1: return BINOCLE_PIXEL_GRAY16;
    case CV_8UC3: return BINOCLE_PIXEL_BGR8;
    case CV_32FC1: return BINOCLE_PIXEL_FLOAT32;
    default: throw Error("image type " + std::to_string(m.type()) + " cannot cross the plugin ABI");
    }
}

std::string checkFrame(const binocle_stereo_frame &f) {
    std::string bad = checkImage(f.left, "left image");
    if (bad.empty()) bad = checkImage(f.right, "right image");
    if (bad.empty() && (f.left.width != f.right.width || f.left.height != f.right.height || f.left.format != f.right.format))
        bad = "left and right images differ: " + std::to_string(f.left.width) + "x" + std::to_string(f.left.height) +
              " format " + std::to_string(f.left.format) + " vs " + std::to_string(f.right.width) + "x" +
              std::to_string(f.right.height) + " format " + std::to_string(f.right.format);
    if (bad.empty() && (f.left.format == BINOCLE_PIXEL_FLOAT32 || f.left.format == BINOCLE_PIXEL_GRAY16))
        bad = "left/right images must be GRAY8, BGR8 or RGB8";
    if (bad.empty() && (f.extra_count < 0 || f.extra_count > 64 || (f.extra_count > 0 && !f.extras)))
        bad = "garbage extra plane count " + std::to_string(f.extra_count);
    for (int32_t i = 0; bad.empty() && i < f.extra_count; ++i) {
        std::string name = f.extras[i].name ? f.extras[i].name : "(unnamed)";
        bad = checkImage(f.extras[i].image, ("extra plane '" + name + "'").c_str());
    }
    return bad;
}

} // namespace binocle
