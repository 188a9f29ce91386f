// SPDX-License-Identifier: MIT
// Fuzz harness: the index of a recording (frames.csv), as the SDK's reader
// (binocle/recording.hpp) reads it for the replay source. Every path it accepts must stay
// inside the recording folder, and every row it keeps must write back as it was read.
#include <binocle/recording.hpp>

#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string text(reinterpret_cast<const char *>(data), size);
    try {
        const auto index = binocle::recording::parseIndex(text, "frames.csv");
        for (const auto &r : index.rows) {
            if (!binocle::sdk::isConfinedRelativePath(r.left) || !binocle::sdk::isConfinedRelativePath(r.right)) std::abort();
            if (r.sequence < 0) std::abort();
        }
    } catch (const binocle::sdk::Error &) {
    }
    return 0;
}
