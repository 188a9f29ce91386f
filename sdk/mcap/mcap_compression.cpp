// SPDX-License-Identifier: MIT
// CRC-32 and chunk compression of MCAP: zstd frames and LZ4 frames, through libzstd and liblz4.
#include "mcap_bytes.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <array>

namespace binocle::mcap {

namespace {
std::array<uint32_t, 256> crcTable() {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
        uint32_t c = i;
        for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        t[i] = c;
    }
    return t;
}
} // namespace

uint32_t crc32(const uint8_t *data, size_t size, uint32_t crc) {
    static const std::array<uint32_t, 256> table = crcTable();
    crc = ~crc;
    for (size_t i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
    return ~crc;
}

const char *compressionName(Compression c) {
    switch (c) {
    case Compression::Zstd: return "zstd";
    case Compression::Lz4: return "lz4";
    default: return "";
    }
}

namespace detail {

std::vector<uint8_t> compress(Compression c, int level, const uint8_t *data, size_t size) {
    std::vector<uint8_t> out;
    if (c == Compression::Zstd) {
        out.resize(ZSTD_compressBound(size));
        const size_t n = ZSTD_compress(out.data(), out.size(), data, size, level);
        if (ZSTD_isError(n)) throw Error(std::string("mcap: zstd compression failed: ") + ZSTD_getErrorName(n));
        out.resize(n);
    } else if (c == Compression::Lz4) {
        LZ4F_preferences_t prefs{};
        prefs.frameInfo.contentSize = size;
        out.resize(LZ4F_compressFrameBound(size, &prefs));
        const size_t n = LZ4F_compressFrame(out.data(), out.size(), data, size, &prefs);
        if (LZ4F_isError(n)) throw Error(std::string("mcap: lz4 compression failed: ") + LZ4F_getErrorName(n));
        out.resize(n);
    } else {
        out.assign(data, data + size);
    }
    return out;
}

void decompress(const std::string &compression, const uint8_t *data, size_t size, uint8_t *out, size_t expected,
                const std::string &where) {
    if (compression.empty()) {
        if (size != expected)
            throw Error(where + ": uncompressed chunk holds " + std::to_string(size) + " bytes but its uncompressed_size says " +
                        std::to_string(expected));
        if (size) std::memcpy(out, data, size);
        return;
    }
    if (compression == "zstd") {
        const size_t n = ZSTD_decompress(out, expected, data, size);
        if (ZSTD_isError(n))
            throw Error(where + ": zstd data does not decompress to the " + std::to_string(expected) +
                        " bytes its uncompressed_size says (" + ZSTD_getErrorName(n) + ")");
        if (n != expected)
            throw Error(where + ": zstd data decompresses to " + std::to_string(n) + " bytes but uncompressed_size says " +
                        std::to_string(expected));
        return;
    }
    if (compression == "lz4") {
        LZ4F_dctx *ctx = nullptr;
        if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) throw Error(where + ": lz4: out of memory");
        size_t in = 0, made = 0;
        size_t status = 1;
        while (in < size && made < expected && status != 0) {
            size_t srcLen = size - in, dstLen = expected - made;
            status = LZ4F_decompress(ctx, out + made, &dstLen, data + in, &srcLen, nullptr);
            if (LZ4F_isError(status)) {
                LZ4F_freeDecompressionContext(ctx);
                throw Error(where + ": lz4 data is not a valid LZ4 frame (" + LZ4F_getErrorName(status) + ")");
            }
            in += srcLen;
            made += dstLen;
            if (srcLen == 0 && dstLen == 0) break;
        }
        // The output is full: a frame that goes on is larger than the chunk says.
        if (status != 0 && made == expected && in < size) {
            uint8_t probe = 0;
            size_t srcLen = size - in, dstLen = 1;
            status = LZ4F_decompress(ctx, &probe, &dstLen, data + in, &srcLen, nullptr);
            if (!LZ4F_isError(status) && dstLen > 0) made = expected + 1;
        }
        LZ4F_freeDecompressionContext(ctx);
        if (made != expected || (status != 0 && made == expected && in < size))
            throw Error(where + ": lz4 data decompresses to " + (made > expected ? "more than " : "") +
                        std::to_string(made > expected ? expected : made) + " bytes but uncompressed_size says " +
                        std::to_string(expected));
        return;
    }
    throw Error(where + ": unknown compression '" + sdk::printable(compression, 40) +
                "'; expected zstd, lz4 or none (\"\")");
}

} // namespace detail
} // namespace binocle::mcap
