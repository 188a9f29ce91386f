// SPDX-License-Identifier: MIT
// Fuzz harness: Binocle's one PFM path (input::decodePfm: the header is checked against
// the image limits and the data's size, then the data read by the scale's sign), used by the replay
// source's ground truths and by `binocle` itself.
#include "input/image_file.hpp"

#include <cstdint>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    try {
        const cv::Mat m = binocle::input::decodePfm(data, size, "fuzz.pfm");
        // Every pixel came from the file: 4 bytes a sample.
        if (m.total() * m.channels() * 4 > size) std::abort();
    } catch (const binocle::input::ImageFileError &) {
    }
    return 0;
}
