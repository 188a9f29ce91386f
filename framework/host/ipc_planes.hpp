// SPDX-License-Identifier: MIT
// Planes in the shared memory of `isolation: process`: where images and arrays go in a
// region (Layout), and the images, named planes, frames and clouds that point into it,
// each checked on decoding to lie within the region. Internal to host/.
#pragma once

#include "host/ipc_wire.hpp"

#include <binocle/abi.h>

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace binocle::wire {

// Images and arrays laid out one after another in a shared region: each plane gets an
// offset (64-byte aligned) and tightly packed rows.
class Layout {
public:
    // Where `im` goes; an image already placed (same pixels, same description) is placed
    // once. Returns the description of the copy: data is the offset, as an integer.
    binocle_image place(const binocle_image &im);
    // `bytes` of an array; returns its offset.
    uint64_t placeArray(const void *data, uint64_t bytes);
    uint64_t bytes() const { return end_; }
    // Copies every placed plane into `base` (bytes() of it).
    void copyInto(uint8_t *base) const;

private:
    struct Item {
        const void *src;
        uint64_t offset;
        binocle_image image; // as given (source stride), for images
        uint64_t bytes;      // in the region
        bool isImage;
    };
    uint64_t take(uint64_t bytes);
    std::vector<Item> items_;
    uint64_t end_ = 0;
};

// A shared region as the reader sees it: decoded planes are checked to lie within it.
struct Region {
    uint8_t *base = nullptr;
    uint64_t bytes = 0;
};

void putImage(Writer &w, const binocle_image &placed);
// The image at its offset in the region, checked to lie within it.
binocle_image getImage(Reader &r, Region region);
// The array at an offset of the region, checked to lie within it.
uint8_t *arrayAt(uint64_t offset, uint64_t length, Region region);

// Named planes (a frame's extras, a matcher's extras) placed in a Layout: their count,
// then each one's name and image.
void putNamedImages(Writer &w, Layout &layout, const binocle_named_image *images, int32_t count);
// Decoded: the images point into the region, the names into `names`.
struct NamedImages {
    std::vector<binocle_named_image> images;
    std::deque<std::string> names; // a deque: pointers into it stay valid as it grows
};
void getNamedImages(Reader &r, Region region, NamedImages &out);

// A frame whose planes are placed in a Layout.
void putFrame(Writer &w, Layout &layout, const binocle_stereo_frame &f);
// What a decoded frame points into besides the region: extra planes, metadata.
struct FrameTexts {
    NamedImages extras;
    std::string metadata;
};
binocle_stereo_frame getFrame(Reader &r, Region region, FrameTexts &texts);

// A cloud whose arrays are placed in a Layout.
void putCloud(Writer &w, Layout &layout, const binocle_cloud &c);
binocle_cloud getCloud(Reader &r, Region region);

} // namespace binocle::wire
