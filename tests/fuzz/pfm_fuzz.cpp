// SPDX-License-Identifier: MIT
// Fuzz harness: PFM decoding of the replay source (ground truths), bounded by the
// file's size and the image limits before anything is allocated.
#include "replay_metadata.hpp"

#include <binocle/plugin.hpp>

#include <cstdint>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    try {
        const cv::Mat m = binocle::replay::decodePfm(data, size, "fuzz.pfm");
        // Every pixel came from the file: 4 bytes a sample.
        if (m.total() * m.channels() * 4 > size) std::abort();
    } catch (const binocle::sdk::Error &) {
    }
    return 0;
}
