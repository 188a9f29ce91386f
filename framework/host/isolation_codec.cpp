// SPDX-License-Identifier: MIT
// The wire codec of `isolation: process`: transport, requests, messages, planes in shared
// memory and the kinds' calls; each encoder next to its decoder.
#include "host/isolation_codec.hpp"

#include "host/plugin_kinds.hpp"

#include <algorithm>
#include <cerrno>
#include <cstddef>
#include <sys/socket.h>
#include <unistd.h>

namespace binocle::wire {

// ---- Transport --------------------------------------------------------------------------------

namespace {

// A SOCK_SEQPACKET message must fit the socket's buffer (about 200 kB by default):
// larger ones (a rig's YAML, a long statistics text) go in chunks, each led by a byte
// that says whether more follow.
constexpr size_t kChunk = 64 * 1024;
constexpr size_t kMaxMessage = 256u << 20;

bool sendChunk(int sock, const char *data, size_t size, bool more, int fd) {
    uint8_t flag = more ? 1 : 0;
    iovec iov[2] = {{&flag, 1}, {const_cast<char *>(data), size}};
    msghdr h{};
    h.msg_iov = iov;
    h.msg_iovlen = 2;
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
    if (fd >= 0) {
        h.msg_control = control;
        h.msg_controllen = sizeof control;
        cmsghdr *c = CMSG_FIRSTHDR(&h);
        c->cmsg_level = SOL_SOCKET;
        c->cmsg_type = SCM_RIGHTS;
        c->cmsg_len = CMSG_LEN(sizeof(int));
        std::memcpy(CMSG_DATA(c), &fd, sizeof fd);
    }
    ssize_t n;
    do {
        n = ::sendmsg(sock, &h, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    return n == static_cast<ssize_t>(size + 1);
}

} // namespace

bool sendMessage(int sock, const std::string &msg, int fd) {
    size_t at = 0;
    do {
        const size_t n = std::min(kChunk, msg.size() - at);
        const bool more = at + n < msg.size();
        if (!sendChunk(sock, msg.data() + at, n, more, at == 0 ? fd : -1)) return false;
        at += n;
    } while (at < msg.size());
    return true;
}

bool receiveMessage(int sock, std::string &msg, int *fd) {
    msg.clear();
    if (fd) *fd = -1;
    std::string chunk(kChunk + 1, '\0');
    for (;;) {
        iovec iov{chunk.data(), chunk.size()};
        msghdr h{};
        h.msg_iov = &iov;
        h.msg_iovlen = 1;
        alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
        h.msg_control = control;
        h.msg_controllen = sizeof control;
        ssize_t n;
        do {
            n = ::recvmsg(sock, &h, MSG_CMSG_CLOEXEC);
        } while (n < 0 && errno == EINTR);
        if (n <= 0) return false;
        for (cmsghdr *c = CMSG_FIRSTHDR(&h); c; c = CMSG_NXTHDR(&h, c))
            if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_RIGHTS) {
                int received = -1;
                std::memcpy(&received, CMSG_DATA(c), sizeof(int));
                if (fd && *fd < 0) *fd = received;
                else ::close(received);
            }
        msg.append(chunk.data() + 1, static_cast<size_t>(n) - 1);
        if (chunk[0] == 0) return true;
        if (msg.size() > kMaxMessage) return false;
    }
}

// ---- Requests -----------------------------------------------------------------------------------

void putParams(Writer &w, const ParamValues &params) {
    w.put<int32_t>(params.size());
    for (int32_t i = 0; i < params.size(); ++i) {
        const binocle_param &p = params.data()[i];
        w.str(p.name ? p.name : "").put<int32_t>(p.type).put<int64_t>(p.i).put<double>(p.d);
        w.cstr(p.s).put<int32_t>(p.explicit_);
    }
}

ParamValues getParams(Reader &r) {
    ParamValues values;
    const auto n = r.get<int32_t>();
    for (int32_t i = 0; i < n; ++i) {
        const std::string name = r.str();
        const auto type = r.get<int32_t>();
        const auto iv = r.get<int64_t>();
        const auto dv = r.get<double>();
        const auto [hasText, text] = r.cstr();
        const bool isExplicit = r.get<int32_t>() != 0;
        if (hasText) values.setText(name, type, text, isExplicit);
        else if (type == BINOCLE_PARAM_DOUBLE) values.setDouble(name, dv, isExplicit);
        else if (type == BINOCLE_PARAM_BOOL) values.setBool(name, iv != 0, isExplicit);
        else values.setInt(name, iv, isExplicit);
    }
    return values;
}

void putCreate(Writer &w, int32_t kind, const ParamValues &params) {
    w.put<int32_t>(kind);
    putParams(w, params);
}

std::pair<int32_t, ParamValues> getCreate(Reader &r) {
    const auto kind = r.get<int32_t>();
    return {kind, getParams(r)};
}

// ---- Messages -----------------------------------------------------------------------------------

std::string encodeReply(int32_t rc, const std::string &message, const std::string &payload) {
    Writer w;
    w.put<uint32_t>(kReply);
    put(w, ReplyHead{rc, message});
    return w.raw(payload).data();
}

void putDescription(Writer &w, const binocle_plugin_header &h, const std::vector<binocle_param_desc> &params) {
    w.put<uint32_t>(h.struct_size).put<uint32_t>(h.abi_version).put<uint32_t>(h.api_version).put<int32_t>(h.kind);
    w.cstr(h.name).cstr(h.version).cstr(h.description);
    w.put<int32_t>(static_cast<int32_t>(params.size()));
    for (const auto &d : params) {
        w.cstr(d.name).put<int32_t>(d.type).put<uint32_t>(d.flags).cstr(d.default_value);
        w.put<double>(d.min).put<double>(d.max).put<int64_t>(d.multiple_of);
        w.cstr(d.choices).cstr(d.unit).cstr(d.help);
    }
}

namespace {

// What a described record points into: its table (the kind's size, zeros but for the
// header and the settings), the texts and the settings table, owned.
struct Described {
    std::vector<std::max_align_t> table;
    binocle_plugin_header &header() { return *reinterpret_cast<binocle_plugin_header *>(table.data()); }
    std::vector<binocle_param_desc> params;
    std::deque<std::string> texts; // a deque: pointers into it stay valid as it grows
    const char *keep(const std::pair<bool, std::string> &t) {
        if (!t.first) return nullptr;
        texts.push_back(t.second);
        return texts.back().c_str();
    }
};

} // namespace

PluginRecord getDescription(Reader &r, const std::string &path) {
    auto d = std::make_shared<Described>();
    const auto structSize = r.get<uint32_t>();
    const auto abiVersion = r.get<uint32_t>();
    const auto apiVersion = r.get<uint32_t>();
    const PluginKind *kind = pluginKind(r.get<int32_t>());
    if (!kind) throw Error("malformed plugin kind from the plugin helper");
    d->table.assign((kind->tableSize + sizeof(std::max_align_t) - 1) / sizeof(std::max_align_t), std::max_align_t{});
    binocle_plugin_header &h = d->header();
    h.struct_size = structSize;
    h.abi_version = abiVersion;
    h.api_version = apiVersion;
    h.kind = kind->kind;
    h.name = d->keep(r.cstr());
    h.version = d->keep(r.cstr());
    h.description = d->keep(r.cstr());
    const auto count = r.get<int32_t>();
    if (count < 0 || count > 1000) throw Error("malformed settings table from the plugin helper");
    for (int32_t i = 0; i < count; ++i) {
        binocle_param_desc p{};
        p.name = d->keep(r.cstr());
        p.type = r.get<int32_t>();
        p.flags = r.get<uint32_t>();
        p.default_value = d->keep(r.cstr());
        p.min = r.get<double>();
        p.max = r.get<double>();
        p.multiple_of = r.get<int64_t>();
        p.choices = d->keep(r.cstr());
        p.unit = d->keep(r.cstr());
        p.help = d->keep(r.cstr());
        d->params.push_back(p);
    }
    kind->setParams(&h, d->params.empty() ? nullptr : d->params.data(), count);
    PluginRecord rec;
    rec.path = path;
    rec.name = h.name ? h.name : "";
    rec.version = h.version ? h.version : "";
    rec.description = h.description ? h.description : "";
    rec.kind = h.kind;
    rec.abi_version = h.abi_version;
    rec.api_version = h.api_version;
    rec.table = &h;
    rec.tableStorage = d;
    rec.described = true;
    return rec;
}

// ---- Planes in shared memory --------------------------------------------------------------------

uint64_t Layout::take(uint64_t bytes) {
    const uint64_t offset = (end_ + 63) / 64 * 64;
    end_ = offset + bytes;
    return offset;
}

binocle_image Layout::place(const binocle_image &im) {
    for (const auto &it : items_)
        if (it.isImage && it.src == im.data && it.image.width == im.width && it.image.height == im.height &&
            it.image.format == im.format && it.image.stride_bytes == im.stride_bytes) {
            binocle_image out = im;
            out.stride_bytes = im.width * bytesPerPixel(im.format);
            out.data = reinterpret_cast<void *>(static_cast<uintptr_t>(it.offset));
            return out;
        }
    const uint64_t row = static_cast<uint64_t>(std::max(im.width, 0)) * bytesPerPixel(im.format);
    const uint64_t bytes = row * static_cast<uint64_t>(std::max(im.height, 0));
    Item it{im.data, take(bytes), im, bytes, true};
    items_.push_back(it);
    binocle_image out = im;
    out.stride_bytes = static_cast<int32_t>(row);
    out.data = reinterpret_cast<void *>(static_cast<uintptr_t>(it.offset));
    return out;
}

uint64_t Layout::placeArray(const void *data, uint64_t bytes) {
    Item it{data, take(bytes), binocle_image{}, bytes, false};
    items_.push_back(it);
    return it.offset;
}

void Layout::copyInto(uint8_t *base) const {
    for (const auto &it : items_) {
        if (!it.src || it.bytes == 0) continue;
        if (!it.isImage) {
            std::memcpy(base + it.offset, it.src, it.bytes);
            continue;
        }
        const size_t row = static_cast<size_t>(it.image.width) * bytesPerPixel(it.image.format);
        const auto *src = static_cast<const uint8_t *>(it.src);
        if (static_cast<size_t>(it.image.stride_bytes) == row) {
            std::memcpy(base + it.offset, src, it.bytes);
        } else {
            for (int32_t y = 0; y < it.image.height; ++y)
                std::memcpy(base + it.offset + y * row, src + static_cast<size_t>(y) * it.image.stride_bytes, row);
        }
    }
}

void putImage(Writer &w, const binocle_image &placed) {
    put(w, placed);
    w.put<uint64_t>(reinterpret_cast<uintptr_t>(placed.data));
}

binocle_image getImage(Reader &r, Region region) {
    binocle_image im = get<binocle_image>(r);
    const auto offset = r.get<uint64_t>();
    const int bpp = bytesPerPixel(im.format);
    if (im.width < 0 || im.height < 0 || bpp == 0 || im.stride_bytes < static_cast<int64_t>(im.width) * bpp)
        throw Error("malformed image description between Binocle and its plugin helper");
    im.data = arrayAt(offset, static_cast<uint64_t>(im.stride_bytes) * im.height, region);
    return im;
}

uint8_t *arrayAt(uint64_t offset, uint64_t length, Region region) {
    if (!region.base || offset > region.bytes || length > region.bytes - offset)
        throw Error("an image or array lies outside the shared memory between Binocle and its plugin helper");
    return region.base + offset;
}

void putNamedImages(Writer &w, Layout &layout, const binocle_named_image *images, int32_t count) {
    w.put<int32_t>(count);
    for (int32_t i = 0; i < count; ++i) {
        w.str(images[i].name ? images[i].name : "");
        putImage(w, layout.place(images[i].image));
    }
}

void getNamedImages(Reader &r, Region region, NamedImages &out) {
    const auto count = r.get<int32_t>();
    if (count < 0 || count > 64) throw Error("malformed list of planes between Binocle and its plugin helper");
    out.images.clear();
    out.names.clear();
    for (int32_t i = 0; i < count; ++i) {
        out.names.push_back(r.str());
        out.images.push_back({out.names.back().c_str(), getImage(r, region)});
    }
}

void putFrame(Writer &w, Layout &layout, const binocle_stereo_frame &f) {
    w.put<uint64_t>(f.sequence).put<int64_t>(f.timestamp_left_ns).put<int64_t>(f.timestamp_right_ns);
    putImage(w, layout.place(f.left));
    putImage(w, layout.place(f.right));
    putNamedImages(w, layout, f.extras, f.extra_count);
    w.cstr(f.metadata);
}

binocle_stereo_frame getFrame(Reader &r, Region region, FrameTexts &texts) {
    binocle_stereo_frame f{};
    f.struct_size = sizeof f;
    f.sequence = r.get<uint64_t>();
    f.timestamp_left_ns = r.get<int64_t>();
    f.timestamp_right_ns = r.get<int64_t>();
    f.left = getImage(r, region);
    f.right = getImage(r, region);
    getNamedImages(r, region, texts.extras);
    f.extras = texts.extras.images.empty() ? nullptr : texts.extras.images.data();
    f.extra_count = static_cast<int32_t>(texts.extras.images.size());
    const auto [hasMetadata, metadata] = r.cstr();
    texts.metadata = metadata;
    f.metadata = hasMetadata ? texts.metadata.c_str() : nullptr;
    return f;
}

void putCloud(Writer &w, Layout &layout, const binocle_cloud &c) {
    const uint64_t n = static_cast<uint64_t>(std::max<int64_t>(c.count, 0));
    put(w, c);
    w.put<uint64_t>(layout.placeArray(c.xyz, 3 * n * sizeof(float)));
    w.put<uint8_t>(c.rgb != nullptr).put<uint64_t>(c.rgb ? layout.placeArray(c.rgb, 3 * n) : 0);
    w.put<uint8_t>(c.pixel != nullptr).put<uint64_t>(c.pixel ? layout.placeArray(c.pixel, n * sizeof(int32_t)) : 0);
}

binocle_cloud getCloud(Reader &r, Region region) {
    binocle_cloud c = get<binocle_cloud>(r);
    if (c.count < 0) throw Error("malformed cloud between Binocle and its plugin helper");
    const uint64_t n = static_cast<uint64_t>(c.count);
    c.xyz = reinterpret_cast<float *>(arrayAt(r.get<uint64_t>(), 3 * n * sizeof(float), region));
    const bool rgb = r.get<uint8_t>() != 0;
    const auto rgbAt = r.get<uint64_t>();
    if (rgb) c.rgb = arrayAt(rgbAt, 3 * n, region);
    const bool pixel = r.get<uint8_t>() != 0;
    const auto pixelAt = r.get<uint64_t>();
    if (pixel) c.pixel = reinterpret_cast<int32_t *>(arrayAt(pixelAt, n * sizeof(int32_t), region));
    return c;
}

// ---- The kinds' calls ----------------------------------------------------------------------------

void putRange(Writer &w, std::pair<int32_t, int32_t> range) { w.put<int32_t>(range.first).put<int32_t>(range.second); }

std::pair<int32_t, int32_t> getRange(Reader &r) {
    const auto first = r.get<int32_t>();
    return {first, r.get<int32_t>()};
}

void putGrabRequest(Writer &w, int32_t timeout_ms) { w.put<int32_t>(timeout_ms); }
int32_t getGrabRequest(Reader &r) { return r.get<int32_t>(); }

void putEvaluate(Writer &w, Layout &layout, const binocle_eval_input &in, bool sendCalibration, bool sendRig) {
    w.put<uint8_t>(in.frame != nullptr);
    if (in.frame) putFrame(w, layout, *in.frame);
    for (const binocle_image *im : {in.rectified_left, in.rectified_right, in.disparity}) {
        w.put<uint8_t>(im != nullptr);
        if (im) putImage(w, layout.place(*im));
    }
    w.put<uint8_t>(in.cloud != nullptr);
    if (in.cloud) putCloud(w, layout, *in.cloud);
    // A text the helper process has already: a byte that says "the same as before".
    w.put<uint8_t>(!sendCalibration);
    if (sendCalibration) w.cstr(in.calibration_yaml);
    w.put<uint8_t>(!sendRig);
    if (sendRig) w.cstr(in.rig_yaml);
    w.cstr(in.output_dir);
    // What the host knows of the matcher's search and the ground pose (appended members).
    w.put<int32_t>(in.min_disparity).put<int32_t>(in.num_disparities).put<int32_t>(in.ground_pose_known);
    w.put<double>(in.camera_height_mm).put<double>(in.inclination_deg);
    // The matcher's planes (appended members).
    putNamedImages(w, layout, in.disparity_extras, in.disparity_extras ? in.disparity_extra_count : 0);
}

void getEvaluate(Reader &r, Region region, EvaluateTexts &texts, EvaluateInput &out) {
    const bool hasFrame = r.get<uint8_t>() != 0;
    if (hasFrame) out.frame = getFrame(r, region, out.frameTexts);
    bool has[3];
    for (int i = 0; i < 3; ++i) {
        has[i] = r.get<uint8_t>() != 0;
        if (has[i]) out.images[i] = getImage(r, region);
    }
    const bool hasCloud = r.get<uint8_t>() != 0;
    if (hasCloud) out.cloud = getCloud(r, region);
    for (auto *text : {&texts.calibration, &texts.rig})
        if (r.get<uint8_t>() == 0) *text = r.cstr(); // else: the same as before
    out.output = r.cstr();
    binocle_eval_input &in = out.in;
    in = binocle_eval_input{};
    in.min_disparity = r.get<int32_t>();
    in.num_disparities = r.get<int32_t>();
    in.ground_pose_known = r.get<int32_t>();
    in.camera_height_mm = r.get<double>();
    in.inclination_deg = r.get<double>();
    getNamedImages(r, region, out.disparityExtras);
    in.disparity_extras = out.disparityExtras.images.empty() ? nullptr : out.disparityExtras.images.data();
    in.disparity_extra_count = static_cast<int32_t>(out.disparityExtras.images.size());
    in.struct_size = sizeof in;
    in.frame = hasFrame ? &out.frame : nullptr;
    in.rectified_left = has[0] ? &out.images[0] : nullptr;
    in.rectified_right = has[1] ? &out.images[1] : nullptr;
    in.disparity = has[2] ? &out.images[2] : nullptr;
    in.cloud = hasCloud ? &out.cloud : nullptr;
    in.calibration_yaml = texts.calibration.first ? texts.calibration.second.c_str() : nullptr;
    in.rig_yaml = texts.rig.first ? texts.rig.second.c_str() : nullptr;
    in.output_dir = out.output.first ? out.output.second.c_str() : nullptr;
}

} // namespace binocle::wire
