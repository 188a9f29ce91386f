// SPDX-License-Identifier: MIT
// Planes in shared memory: the layout of a region, and images, named planes, frames
// and clouds encoded as offsets into it, each encoder next to its decoder.
#include "host/ipc_planes.hpp"

#include <algorithm>
#include <cstring>

namespace binocle::wire {

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

} // namespace binocle::wire
