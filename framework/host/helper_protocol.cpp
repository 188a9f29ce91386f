// SPDX-License-Identifier: MIT
// The messages between Binocle and binocle-plugin-helper: framing, settings, layouts.
#include "host/helper_protocol.hpp"

#include <algorithm>
#include <cerrno>
#include <deque>
#include <sys/socket.h>
#include <unistd.h>

namespace binocle::helper {

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

std::string encodeParams(const ParamValues &params) {
    Writer w;
    w.put<int32_t>(params.size());
    for (int32_t i = 0; i < params.size(); ++i) {
        const binocle_param &p = params.data()[i];
        w.str(p.name ? p.name : "").put<int32_t>(p.type).put<int64_t>(p.i).put<double>(p.d);
        w.cstr(p.s).put<int32_t>(p.explicit_);
    }
    return w.data();
}

ParamValues decodeParams(Reader &r) {
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

void encodeDescription(Writer &w, const binocle_plugin_header &h, const std::vector<binocle_param_desc> &params) {
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

// What a described record points into: texts and the settings table, owned.
struct Described {
    union {
        binocle_plugin_header header;
        binocle_source_api source;
        binocle_matcher_api matcher;
        binocle_cloud_transform_api transform;
        binocle_evaluator_api evaluator;
    } table;
    std::vector<binocle_param_desc> params;
    std::deque<std::string> texts; // a deque: pointers into it stay valid as it grows
    const char *keep(const std::pair<bool, std::string> &t) {
        if (!t.first) return nullptr;
        texts.push_back(t.second);
        return texts.back().c_str();
    }
};

} // namespace

PluginRecord decodeDescription(Reader &r, const std::string &path) {
    auto d = std::make_shared<Described>();
    std::memset(static_cast<void *>(&d->table), 0, sizeof d->table);
    binocle_plugin_header &h = d->table.header;
    h.struct_size = r.get<uint32_t>();
    h.abi_version = r.get<uint32_t>();
    h.api_version = r.get<uint32_t>();
    h.kind = r.get<int32_t>();
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
    // The params member sits at the same place in every kind's table (after the header).
    const binocle_param_desc *table = d->params.empty() ? nullptr : d->params.data();
    switch (h.kind) {
    case BINOCLE_KIND_STEREO_SOURCE: d->table.source.params = table, d->table.source.param_count = count; break;
    case BINOCLE_KIND_MATCHER: d->table.matcher.params = table, d->table.matcher.param_count = count; break;
    case BINOCLE_KIND_CLOUD_TRANSFORM: d->table.transform.params = table, d->table.transform.param_count = count; break;
    case BINOCLE_KIND_EVALUATOR: d->table.evaluator.params = table, d->table.evaluator.param_count = count; break;
    default: throw Error("malformed plugin kind from the plugin helper");
    }
    PluginRecord rec;
    rec.path = path;
    rec.name = h.name ? h.name : "";
    rec.version = h.version ? h.version : "";
    rec.description = h.description ? h.description : "";
    rec.kind = h.kind;
    rec.abi_version = h.abi_version;
    rec.api_version = h.api_version;
    rec.table = &d->table.header;
    rec.tableStorage = d;
    rec.described = true;
    return rec;
}

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
    w.put<int32_t>(placed.width).put<int32_t>(placed.height).put<int32_t>(placed.stride_bytes).put<int32_t>(placed.format);
    w.put<uint64_t>(reinterpret_cast<uintptr_t>(placed.data));
}

binocle_image getImage(Reader &r, uint8_t *base, uint64_t bytes) {
    binocle_image im{};
    im.width = r.get<int32_t>();
    im.height = r.get<int32_t>();
    im.stride_bytes = r.get<int32_t>();
    im.format = r.get<int32_t>();
    const auto offset = r.get<uint64_t>();
    const int bpp = bytesPerPixel(im.format);
    if (im.width < 0 || im.height < 0 || bpp == 0 || im.stride_bytes < static_cast<int64_t>(im.width) * bpp)
        throw Error("malformed image description between Binocle and its plugin helper");
    im.data = arrayAt(offset, static_cast<uint64_t>(im.stride_bytes) * im.height, base, bytes);
    return im;
}

uint8_t *arrayAt(uint64_t offset, uint64_t length, uint8_t *base, uint64_t bytes) {
    if (!base || offset > bytes || length > bytes - offset)
        throw Error("an image or array lies outside the shared memory between Binocle and its plugin helper");
    return base + offset;
}

} // namespace binocle::helper
