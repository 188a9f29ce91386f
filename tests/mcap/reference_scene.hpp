// SPDX-License-Identifier: MIT
// The scene of the bags that tests/mcap/node/write_reference.cjs writes with the reference
// writer: the same xorshift32 texture, so that a test checks every pixel it reads back.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

namespace binocle::test {

// The texture of frame `frame`, width x height bytes, row-major.
inline std::vector<uint8_t> referenceTexture(int width, int height, int frame) {
    uint32_t s = (0x9e3779b9u ^ static_cast<uint32_t>(static_cast<uint64_t>(frame) * 0x85ebca6bu)) ;
    if (s == 0) s = 1;
    std::vector<uint8_t> out(static_cast<size_t>(width) * height);
    for (auto &v : out) {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        v = static_cast<uint8_t>(s & 0xff);
    }
    return out;
}

// Pixel (x, y) of side 0 (left) or 1 (right) of frame `frame`: left(x) = tex(x),
// right(x) = tex(x + d), a constant disparity d.
inline uint8_t referencePixel(const std::vector<uint8_t> &texture, int width, int disparity, int side, int x, int y) {
    return texture[static_cast<size_t>(y) * (width + disparity) + x + (side ? disparity : 0)];
}

inline std::string nodeFolder() { return std::string(BINOCLE_SOURCE_DIR) + "/tests/mcap/node"; }

// Empty when the reference packages are installed, else why not.
inline std::string referenceMissing() {
    const std::string f = nodeFolder() + "/node_modules/@mcap/core/package.json";
    if (std::system("command -v node >/dev/null 2>&1") != 0) return "node is not installed";
    if (FILE *p = std::fopen(f.c_str(), "r")) {
        std::fclose(p);
        return {};
    }
    return "the reference packages are not installed: run scripts/install-npm-test-deps.sh";
}

// Runs `command`, returns its stdout; `status` gets the exit status.
inline std::string runCommand(const std::string &command, int &status) {
    std::string out;
    FILE *p = popen(command.c_str(), "r");
    if (!p) {
        status = -1;
        return out;
    }
    char buf[65536];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    status = pclose(p);
    return out;
}

} // namespace binocle::test
