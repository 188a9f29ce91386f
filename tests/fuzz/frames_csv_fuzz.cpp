// SPDX-License-Identifier: MIT
// Fuzz harness: the index of a recording (frames.csv), read by the replay source. Every
// path it accepts must stay inside the recording folder.
#include "replay_metadata.hpp"

#include "input/text.hpp"

#include <binocle/plugin.hpp>

#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string text(reinterpret_cast<const char *>(data), size);
    try {
        const auto index = binocle::replay::parseFramesCsv(text, "frames.csv");
        for (const auto &p : index.pairs)
            if (!binocle::input::isConfinedRelativePath(p.left) || !binocle::input::isConfinedRelativePath(p.right))
                std::abort();
    } catch (const binocle::sdk::Error &) {
    }
    return 0;
}
