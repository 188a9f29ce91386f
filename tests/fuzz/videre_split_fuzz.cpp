// SPDX-License-Identifier: MIT
// Fuzz harness: the Videre interleaved-frame splitter (plugins/videre1394). The input
// gives a frame's geometry (width, height, stride, bytes, decimation, byte order) and
// its pixels; a frame the check accepts is split in a buffer of exactly that many
// bytes, so that AddressSanitizer sees any read or write past it.
#include "videre_source.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace binocle::videre1394 {
// The device layer is chosen at link time (videre_device.hpp); the splitter needs none.
Bus &bus() { throw std::logic_error("videre_split_fuzz: no IEEE-1394 bus"); }
} // namespace binocle::videre1394

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size < 9) return 0;
    const uint32_t width = 1 + (data[0] | (data[1] << 8)) % 160;
    const uint32_t height = 1 + (data[2] | (data[3] << 8)) % 120;
    const auto stride = static_cast<uint32_t>(std::max<int64_t>(0, 2 * int64_t{width} + data[4] % 16 - 4)); // may be short
    const uint32_t bits = data[5] & 1 ? 16 : 8;
    const int decimation = 1 + data[6] % 9; // 1..9: 9 must be refused
    const bool leftFirst = data[7] & 1;
    const int64_t slack = static_cast<int8_t>(data[8]); // bytes more or fewer than the rows need
    const int64_t rows = static_cast<int64_t>(stride) * (height - 1) + 2 * width;
    const int64_t bytes = std::max<int64_t>(0, rows + slack);
    const std::string problem =
        binocle::videre1394::interleavedFrameProblem(width, height, stride, bits, static_cast<uint64_t>(bytes), decimation);
    if (!problem.empty()) return 0;
    std::vector<uint8_t> frame(static_cast<size_t>(bytes));
    if (size > 9)
        for (size_t i = 0; i < frame.size(); ++i) frame[i] = data[9 + i % (size - 9)];
    std::vector<uint8_t> scratch;
    binocle::videre1394::splitInterleaved(frame.data(), width, height, stride, decimation, leftFirst, scratch);
    return 0;
}
