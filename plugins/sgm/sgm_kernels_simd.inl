// SPDX-License-Identifier: MIT
// sgm: the SIMD kernels, written once with OpenCV's universal intrinsics and compiled
// once per instruction set (sgm_kernels_baseline.cpp, sgm_kernels_avx2.cpp,
// sgm_kernels_avx512.cpp: 16-, 32- and 64-byte vectors). The
// including file defines SGM_SIMD_NS, a namespace of its own: the same inline code
// compiled with other flags must not be merged by the linker.
//
// What each kernel computes is stated by its scalar reference (sgm_kernels_scalar.cpp).
#ifndef SGM_SIMD_NS
#error "define SGM_SIMD_NS before including sgm_kernels_simd.inl"
#endif

#include "sgm_kernels.hpp"
#include "sgm_median.hpp"

#include <opencv2/core/hal/intrin.hpp>

#include <algorithm>
#include <cstdlib>
#include <iterator>
#include <utility>

#if CV_SIMD

namespace sgm {
namespace SGM_SIMD_NS {
namespace {

using namespace cv;

constexpr int kLanes8 = v_uint8::nlanes;
constexpr int kLanes16 = v_uint16::nlanes;
constexpr int kLanes64 = v_uint64::nlanes;
// The padding of disparity counts this table takes: whole vectors, and at least the
// AVX2 table's (so that the narrower tables share its buffers).
constexpr int kTableDispAlign = kLanes8 > kDispAlign ? kLanes8 : kDispAlign;
static_assert(kTableDispAlign % kLanes8 == 0 && kMaxPaddedDisp % kTableDispAlign == 0,
              "padded disparity counts must be whole vectors");

// Bits set in each 64-bit lane. OpenCV's 256-bit v_popcount takes two byte-table lookups
// and a sum of absolute differences; AVX-512 VPOPCNTDQ counts them in one instruction.
inline v_uint64 popcount64(const v_uint64 &a) {
#if CV_SIMD_WIDTH == 64 && CV_AVX_512VPOPCNTDQ
    return v_uint64(_mm512_popcnt_epi64(a.val));
#else
    return v_popcount(a);
#endif
}

// AVX-512: a 512-bit vector's least byte (or word) folded into 128 bits, for PHMINPOSUW.
#if CV_SIMD_WIDTH == 64
inline __m128i foldMinU8(const __m512i a) {
    const __m256i h = _mm256_min_epu8(_mm512_castsi512_si256(a), _mm512_extracti64x4_epi64(a, 1));
    return _mm_min_epu8(_mm256_castsi256_si128(h), _mm256_extracti128_si256(h, 1));
}
inline __m128i foldMinU16(const __m512i a) {
    const __m256i h = _mm256_min_epu16(_mm512_castsi512_si256(a), _mm512_extracti64x4_epi64(a, 1));
    return _mm_min_epu16(_mm256_castsi256_si128(h), _mm256_extracti128_si256(h, 1));
}
#endif

// The least byte of a vector: every path's minimum at every pixel, on the serial chain of
// the horizontal paths. With AVX2 the pairs of bytes are first folded into 16-bit lanes
// (shifting a 16-bit lane right by 8 leaves its high byte 0, so the minimum's high byte
// is 0 too), then SSE4.1's PHMINPOSUW takes the least of eight 16-bit lanes at once: six
// instructions where v_reduce_min's halvings take ten.
inline int leastByte(const v_uint8 &a) {
#if CV_AVX2 && CV_SIMD_WIDTH == 32
    __m128i v = _mm_min_epu8(_mm256_castsi256_si128(a.val), _mm256_extracti128_si256(a.val, 1));
    v = _mm_min_epu8(v, _mm_srli_epi16(v, 8));
    return _mm_cvtsi128_si32(_mm_minpos_epu16(v)) & 0xFF;
#elif CV_SIMD_WIDTH == 64
    __m128i v = foldMinU8(a.val);
    v = _mm_min_epu8(v, _mm_srli_epi16(v, 8));
    return _mm_cvtsi128_si32(_mm_minpos_epu16(v)) & 0xFF;
#else
    return v_reduce_min(a);
#endif
}

// The least byte of a vector in every lane: the horizontal chains' minimum, kept in a
// vector (with AVX2 broadcast from PHMINPOSUW's lane 0): no trip through a general
// register and back on the chain's critical path.
inline v_uint8 leastByteEverywhere(const v_uint8 &a) {
#if CV_AVX2 && CV_SIMD_WIDTH == 32
    __m128i v = _mm_min_epu8(_mm256_castsi256_si128(a.val), _mm256_extracti128_si256(a.val, 1));
    v = _mm_min_epu8(v, _mm_srli_epi16(v, 8));
    return v_uint8(_mm256_broadcastb_epi8(_mm_minpos_epu16(v)));
#elif CV_SIMD_WIDTH == 64
    __m128i v = foldMinU8(a.val);
    v = _mm_min_epu8(v, _mm_srli_epi16(v, 8));
    return v_uint8(_mm512_broadcastb_epi8(_mm_minpos_epu16(v)));
#else
    return vx_setall_u8(static_cast<uint8_t>(v_reduce_min(a)));
#endif
}

// The least 16-bit lane, the same way.
inline int leastWord(const v_uint16 &a) {
#if CV_AVX2 && CV_SIMD_WIDTH == 32
    const __m128i v = _mm_min_epu16(_mm256_castsi256_si128(a.val), _mm256_extracti128_si256(a.val, 1));
    return _mm_cvtsi128_si32(_mm_minpos_epu16(v)) & 0xFFFF;
#elif CV_SIMD_WIDTH == 64
    return _mm_cvtsi128_si32(_mm_minpos_epu16(foldMinU16(a.val))) & 0xFFFF;
#else
    return v_reduce_min(a);
#endif
}

// ---- census ----------------------------------------------------------------------------
// kLanes8 pixels at once: the comparison masks of each neighbour are gathered into eight
// byte planes (plane b holds bits 8b..8b+7 of every pixel), then interleaved (zip) into
// one 64-bit word per pixel. A plane is built in a register, its neighbours taken from
// the highest bit down: doubling it and subtracting the mask (all ones = -1) shifts the
// next bit in, with no read-modify-write of memory between two neighbours.
// CW, CH: the window when known at compile time (the default 9 x 7: the loops unroll and
// every neighbour's row and column become constants), 0 when not. Sym: the centre-
// symmetric census (bit k: window pixel k darker than its mirror, pixel cw * ch - 1 - k),
// else the full one (neighbour k, the centre skipped, darker than the centre).
template <int CW, int CH, bool Sym>
void censusRowOf(const uint8_t *const *rows, int width, int runtimeCw, int runtimeCh, uint64_t *out) {
    const int cw = CW > 0 ? CW : runtimeCw, ch = CH > 0 ? CH : runtimeCh;
    const int rx = cw / 2, ry = ch / 2, count = censusBits(cw, ch, Sym), last = cw * ch - 1;
    // Window pixel n of bit k (the centre skipped, full census) and, for Sym, its mirror.
    auto pixelOf = [&](int k) { return Sym || k < ry * cw + rx ? k : k + 1; };
    // Neighbour k: its row and its column offset, in the order of the bits; for Sym the
    // mirror's too.
    const uint8_t *row[64], *mirrorRow[64];
    int offset[64], mirrorOffset[64];
    for (int k = 0; k < count; ++k) {
        const int n = pixelOf(k), m = last - k;
        row[k] = rows[n / cw];
        offset[k] = n % cw - rx;
        mirrorRow[k] = rows[m / cw];
        mirrorOffset[k] = m % cw - rx;
    }
    int x = 0;
    for (; x + kLanes8 <= width; x += kLanes8) {
        const v_uint8 centre = vx_load(rows[ry] + x);
        v_uint8 plane[8];
#pragma GCC unroll 8
        for (int b = 0; b < 8; ++b) {
            v_uint8 p = vx_setzero_u8();
#pragma GCC unroll 8
            for (int i = 7; i >= 0; --i) {
                const int k = 8 * b + i;
                if (k >= count) continue;
                const uint8_t *at = CW > 0 ? rows[pixelOf(k) / cw] + (pixelOf(k) % cw - rx) : row[k] + offset[k];
                const v_uint8 other = !Sym ? centre
                                      : vx_load((CW > 0 ? rows[(last - k) / cw] + ((last - k) % cw - rx)
                                                        : mirrorRow[k] + mirrorOffset[k]) + x);
                p = v_sub_wrap(v_add_wrap(p, p), v_reinterpret_as_u8(vx_load(at + x) < other));
            }
            plane[b] = p;
        }
        // bytes -> 16-bit pairs -> 32-bit quads -> 64-bit words, pixel order kept.
        v_uint8 z[8];
        for (int b = 0; b < 4; ++b) v_zip(plane[2 * b], plane[2 * b + 1], z[2 * b], z[2 * b + 1]);
        v_uint16 w[8]; // w[0..3]: planes 0-3 of pixel quarters 0..3; w[4..7]: planes 4-7
        for (int half = 0; half < 2; ++half) {
            v_zip(v_reinterpret_as_u16(z[half]), v_reinterpret_as_u16(z[2 + half]), w[2 * half], w[2 * half + 1]);
            v_zip(v_reinterpret_as_u16(z[4 + half]), v_reinterpret_as_u16(z[6 + half]), w[4 + 2 * half], w[4 + 2 * half + 1]);
        }
        for (int q = 0; q < 4; ++q) {
            v_uint32 lo, hi;
            v_zip(v_reinterpret_as_u32(w[q]), v_reinterpret_as_u32(w[4 + q]), lo, hi);
            v_store(out + x + (2 * q) * kLanes64, v_reinterpret_as_u64(lo));
            v_store(out + x + (2 * q + 1) * kLanes64, v_reinterpret_as_u64(hi));
        }
    }
    // The last pixels of a row that is not a whole number of vectors.
    for (; x < width; ++x) {
        uint64_t bits = 0;
        for (int k = 0; k < count; ++k) {
            const int n = pixelOf(k), m = Sym ? last - k : ry * cw + rx;
            bits |= static_cast<uint64_t>(rows[n / cw][x + n % cw - rx] < rows[m / cw][x + m % cw - rx]) << k;
        }
        out[x] = bits;
    }
}

void censusRow(const uint8_t *const *rows, int width, int cw, int ch, bool symmetric, uint64_t *out) {
    if (cw == 9 && ch == 7) {
        if (symmetric) censusRowOf<9, 7, true>(rows, width, cw, ch, out);
        else censusRowOf<9, 7, false>(rows, width, cw, ch, out);
    } else if (symmetric) {
        censusRowOf<0, 0, true>(rows, width, cw, ch, out);
    } else {
        censusRowOf<0, 0, false>(rows, width, cw, ch, out);
    }
}

// ---- costs ----------------------------------------------------------------------------
// The candidates of pixel x, right[x - minD - d] for d = 0, 1, ..., run backwards through
// the right census row. The row is reversed (rev[j] = right[width - 1 - j]) and split by
// residue (plane s holds rev[8q + s]) so that one vector load of plane (r + k) mod 8
// gives the candidates d = 8i + k (lane i) of a block: after popcount each 64-bit lane
// holds one cost in its low byte, and shifting plane k's costs by 8k bits and OR-ing the
// eight puts cost d at byte d, in order.
size_t planeWords(int width, int minD, int paddedDisp) {
    return static_cast<size_t>((width + minD + paddedDisp + 8) / 8 + kLanes64 + 2);
}

size_t costScratch(int width, int minD, int paddedDisp) { return 8 * planeWords(width, minD, paddedDisp); }

#if CV_SIMD_WIDTH == 64
// AVX-512: the eight counts of a vector of candidates (count s of lane i: candidate 8i + s)
// into bytes: two counts a byte permute (VBMI), which zeroes the other six bytes of each
// lane, then the four OR'd: 6 instructions where the shifts and ORs take 14.
struct CountBytes {
    __m512i index[4];
    CountBytes() {
        for (int t = 0; t < 4; ++t) {
            alignas(64) uint8_t at[64];
            for (int j = 0; j < 64; ++j) at[j] = static_cast<uint8_t>((j & ~7) | (j % 8 == 2 * t + 1 ? 64 : 0));
            index[t] = _mm512_load_si512(at);
        }
    }
    inline __attribute__((always_inline)) v_uint8 operator()(const v_uint64 *count) const {
        __m512i pair[4];
#pragma GCC unroll 4
        for (int t = 0; t < 4; ++t)
            pair[t] = _mm512_maskz_permutex2var_epi8(__mmask64{0x0303030303030303ull} << (2 * t), count[2 * t].val,
                                                     index[t], count[2 * t + 1].val);
        return v_uint8(_mm512_or_si512(_mm512_ternarylogic_epi64(pair[0], pair[1], pair[2], 0xFE), pair[3]));
    }
};
#endif

void costRow(const uint64_t *left, const uint64_t *right, int width, int minD, int numDisp, int paddedDisp,
             uint64_t *scratch, uint8_t *cost) {
    const size_t words = planeWords(width, minD, paddedDisp);
    for (int s = 0; s < 8; ++s) {
        uint64_t *plane = scratch + s * words;
        // Words of the row (no test a word), then zeros.
        const size_t inside = width > s ? static_cast<size_t>(width - s + 7) / 8 : 0;
        const uint64_t *from = right + width - 1 - s;
        for (size_t q = 0; q < inside; ++q) plane[q] = from[-8 * static_cast<ptrdiff_t>(q)];
        for (size_t q = inside; q < words; ++q) plane[q] = 0;
    }
    // planes[s]: plane s mod 8, one word further on for s >= 8.
    const uint64_t *planes[16];
    for (int s = 0; s < 16; ++s) planes[s] = scratch + (s & 7) * words + (s >> 3);
    alignas(64) uint8_t iotaBytes[kLanes8];
    for (int i = 0; i < kLanes8; ++i) iotaBytes[i] = static_cast<uint8_t>(i);
    const v_uint8 iota = vx_load_aligned(iotaBytes);
    const v_uint8 invalid = vx_setall_u8(kCostInvalid);
#if CV_SIMD_WIDTH == 64
    const CountBytes countBytes;
#endif
    for (int x = 0; x < width; ++x) {
        const v_uint64 centre = vx_setall_u64(left[x]);
        const int base = width - 1 - x + minD;
        // Lanes d < valid are real candidates: inside the right image and below numDisp.
        const int valid = std::min(numDisp, x - minD + 1);
        uint8_t *out = cost + static_cast<size_t>(x) * paddedDisp;
        for (int d0 = 0; d0 < paddedDisp; d0 += kLanes8) {
            const int at = base + d0, q = at >> 3;
            const uint64_t *const *p = planes + (at & 7);
#if CV_SIMD_WIDTH == 64
            v_uint64 count[8];
#pragma GCC unroll 8
            for (int k = 0; k < 8; ++k) count[k] = popcount64(vx_load(p[k] + q) ^ centre);
            v_uint8 c = countBytes(count);
#else
            // Written out: constant shifts, and two independent halves.
            const v_uint64 w0 = popcount64(vx_load(p[0] + q) ^ centre) | v_shl<8>(popcount64(vx_load(p[1] + q) ^ centre)) |
                                v_shl<16>(popcount64(vx_load(p[2] + q) ^ centre)) |
                                v_shl<24>(popcount64(vx_load(p[3] + q) ^ centre));
            const v_uint64 w1 = popcount64(vx_load(p[4] + q) ^ centre) | v_shl<8>(popcount64(vx_load(p[5] + q) ^ centre)) |
                                v_shl<16>(popcount64(vx_load(p[6] + q) ^ centre)) |
                                v_shl<24>(popcount64(vx_load(p[7] + q) ^ centre));
            v_uint8 c = v_reinterpret_as_u8(w0 | v_shl<32>(w1));
#endif
            const int lanes = valid - d0;
            if (lanes < kLanes8) c = v_select(iota < vx_setall_u8(static_cast<uint8_t>(lanes > 0 ? lanes : 0)), c, invalid);
            v_store(out + d0, c);
        }
    }
}

// The same for census words below 2^32, on 32-bit lanes: the reversed row split by
// residue mod 4 (plane s holds rev[4q + s]), four planes of 32-bit words; one load of
// plane (r + k) mod 4 gives candidates d = 4i + k (lane i), and the four planes' costs,
// shifted by 8k bits, fill the bytes in order: half the loads and popcounts a candidate.
inline v_uint32 popcount32(const v_uint32 &a) {
#if CV_SIMD_WIDTH == 64 && CV_AVX_512VPOPCNTDQ
    return v_uint32(_mm512_popcnt_epi32(a.val));
#else
    return v_popcount(a);
#endif
}

void costRow32(const uint64_t *left, const uint64_t *right, int width, int minD, int numDisp, int paddedDisp,
               uint64_t *scratch64, uint8_t *cost) {
    constexpr int kLanes32 = v_uint32::nlanes;
    // Words of a plane: as planeWords for 8 planes of 64-bit words, which bounds these.
    const size_t words = static_cast<size_t>((width + minD + paddedDisp + 4) / 4 + kLanes32 + 2);
    uint32_t *scratch = reinterpret_cast<uint32_t *>(scratch64);
    for (int s = 0; s < 4; ++s) {
        uint32_t *plane = scratch + s * words;
        // Words of the row (no test a word), then zeros.
        const size_t inside = width > s ? static_cast<size_t>(width - s + 3) / 4 : 0;
        const uint64_t *from = right + width - 1 - s;
        for (size_t q = 0; q < inside; ++q) plane[q] = static_cast<uint32_t>(from[-4 * static_cast<ptrdiff_t>(q)]);
        for (size_t q = inside; q < words; ++q) plane[q] = 0;
    }
    // planes[s]: plane s mod 4, one word further on for s >= 4.
    const uint32_t *planes[8];
    for (int s = 0; s < 8; ++s) planes[s] = scratch + (s & 3) * words + (s >> 2);
    alignas(64) uint8_t iotaBytes[kLanes8];
    for (int i = 0; i < kLanes8; ++i) iotaBytes[i] = static_cast<uint8_t>(i);
    const v_uint8 iota = vx_load_aligned(iotaBytes);
    const v_uint8 invalid = vx_setall_u8(kCostInvalid);
    for (int x = 0; x < width; ++x) {
        const v_uint32 centre = vx_setall_u32(static_cast<uint32_t>(left[x]));
        const int base = width - 1 - x + minD;
        const int valid = std::min(numDisp, x - minD + 1);
        uint8_t *out = cost + static_cast<size_t>(x) * paddedDisp;
        for (int d0 = 0; d0 < paddedDisp; d0 += kLanes8) {
            const int at = base + d0, q = at >> 2;
            const uint32_t *const *p = planes + (at & 3);
            const v_uint32 w = popcount32(vx_load(p[0] + q) ^ centre) | v_shl<8>(popcount32(vx_load(p[1] + q) ^ centre)) |
                               v_shl<16>(popcount32(vx_load(p[2] + q) ^ centre)) |
                               v_shl<24>(popcount32(vx_load(p[3] + q) ^ centre));
            v_uint8 c = v_reinterpret_as_u8(w);
            const int lanes = valid - d0;
            if (lanes < kLanes8) c = v_select(iota < vx_setall_u8(static_cast<uint8_t>(lanes > 0 ? lanes : 0)), c, invalid);
            v_store(out + d0, c);
        }
    }
}

// ---- paths ----------------------------------------------------------------------------
struct Fresh {
    uint8_t data[kMaxPaddedDisp + 2 * kLanes8 + 2];
    Fresh() {
        for (auto &v : data) v = kCostInvalid;
    }
};
const uint8_t *freshPath() {
    static const Fresh fresh;
    return fresh.data + 1;
}

// L(p, d) = C(p, d) + min(L(q, d), L(q, d +- 1) + P1, min L(q) + P2) - min L(q) for the
// paths of a row side by side, pixel by pixel, so that the 16-bit sums are read and
// written once per pixel whatever the number of paths.
// The number of paths is a template argument: the per-path vectors stay in registers.
template <int n>
void pathRowOf(const uint8_t *cost, int width, int paddedDisp, const RowPaths &paths, const uint8_t *grey,
               const uint8_t *greyPrev, const PathParams &pp, uint16_t *sum, bool initSum) {
    const int stride = pathStride(paddedDisp);
    const v_uint8 p1 = vx_setall_u8(static_cast<uint8_t>(pp.p1));
    for (int x = 0; x < width; ++x) {
        const uint8_t *prev[kMaxRowPaths];
        uint8_t *out[kMaxRowPaths];
        v_uint8 base[kMaxRowPaths], jump[kMaxRowPaths], least[kMaxRowPaths];
        for (int i = 0; i < n; ++i) {
            const int xp = x + paths.dx[i];
            const bool has = paths.prevL[i] && xp >= 0 && xp < width;
            prev[i] = has ? paths.prevL[i] + static_cast<size_t>(xp) * stride + 1 : freshPath();
            const int minPrev = has ? paths.prevMin[i][xp] : 255;
            const int p2 = has ? pp.p2ByStep[grey[x] - greyPrev[xp]] : pp.p2ByStep[0];
            base[i] = vx_setall_u8(static_cast<uint8_t>(minPrev));
            jump[i] = base[i] + vx_setall_u8(static_cast<uint8_t>(p2));
            least[i] = vx_setall_u8(255);
            out[i] = paths.curL[i] + static_cast<size_t>(x) * stride + 1;
        }
        const uint8_t *c0 = cost + static_cast<size_t>(x) * paddedDisp;
        if (!sum) { // the costs only: no sums to read or write
            for (int d = 0; d < paddedDisp; d += kLanes8) {
                const v_uint8 c = vx_load(c0 + d);
                for (int i = 0; i < n; ++i) {
                    const uint8_t *q = prev[i] + d;
                    const v_uint8 steps = v_min(vx_load(q - 1), vx_load(q + 1)) + p1;
                    const v_uint8 l = c + (v_min(v_min(vx_load(q), steps), jump[i]) - base[i]);
                    v_store(out[i] + d, l);
                    least[i] = v_min(least[i], l);
                }
            }
            for (int i = 0; i < n; ++i) paths.curMin[i][x] = leastByte(least[i]);
            continue;
        }
        uint16_t *s0 = sum + static_cast<size_t>(x) * paddedDisp;
        for (int d = 0; d < paddedDisp; d += kLanes8) {
            const v_uint8 c = vx_load(c0 + d);
            v_uint16 lo = initSum ? vx_setzero_u16() : vx_load(s0 + d);
            v_uint16 hi = initSum ? vx_setzero_u16() : vx_load(s0 + d + kLanes16);
            for (int i = 0; i < n; ++i) {
                // + and - on 8- and 16-bit lanes saturate in OpenCV's universal intrinsics.
                const uint8_t *q = prev[i] + d;
                const v_uint8 steps = v_min(vx_load(q - 1), vx_load(q + 1)) + p1;
                const v_uint8 t = v_min(v_min(vx_load(q), steps), jump[i]);
                const v_uint8 l = c + (t - base[i]);
                v_store(out[i] + d, l);
                least[i] = v_min(least[i], l);
                v_uint16 l0, l1;
                v_expand(l, l0, l1);
                lo += l0;
                hi += l1;
            }
            v_store(s0 + d, lo);
            v_store(s0 + d + kLanes16, hi);
        }
        for (int i = 0; i < n; ++i) paths.curMin[i][x] = leastByte(least[i]);
    }
}

// One path and no sums (the pass down of 4 paths), Chunks vectors per pixel: unrolled.
template <int Chunks>
void onePathOf(const uint8_t *cost, int width, const RowPaths &paths, const uint8_t *grey, const uint8_t *greyPrev,
               const PathParams &pp) {
    constexpr int paddedDisp = Chunks * kLanes8;
    const int stride = pathStride(paddedDisp);
    const v_uint8 p1 = vx_setall_u8(static_cast<uint8_t>(pp.p1));
    const int dx = paths.dx[0];
    // Local copies: stores through uint8_t pointers may alias the caller's structures.
    const uint8_t *const prevL = paths.prevL[0], *const prevMin = paths.prevMin[0], *const lut = pp.p2ByStep;
    uint8_t *const curL = paths.curL[0], *const curMin = paths.curMin[0];
    for (int x = 0; x < width; ++x) {
        const int xp = x + dx;
        const bool has = prevL && xp >= 0 && xp < width;
        const uint8_t *prev = has ? prevL + static_cast<size_t>(xp) * stride + 1 : freshPath();
        const int minPrev = has ? prevMin[xp] : 255;
        const int p2 = has ? lut[grey[x] - greyPrev[xp]] : lut[0];
        const v_uint8 base = vx_setall_u8(static_cast<uint8_t>(minPrev));
        const v_uint8 jump = base + vx_setall_u8(static_cast<uint8_t>(p2));
        uint8_t *out = curL + static_cast<size_t>(x) * stride + 1;
        const uint8_t *c0 = cost + static_cast<size_t>(x) * paddedDisp;
        v_uint8 least = vx_setall_u8(255);
#pragma GCC unroll 8
        for (int d = 0; d < paddedDisp; d += kLanes8) {
            const uint8_t *q = prev + d;
            const v_uint8 steps = v_min(vx_load(q - 1), vx_load(q + 1)) + p1;
            const v_uint8 l = vx_load(c0 + d) + (v_min(v_min(vx_load(q), steps), jump) - base);
            v_store(out + d, l);
            least = v_min(least, l);
        }
        curMin[x] = leastByte(least);
    }
}

void pathRow(const uint8_t *cost, int width, int paddedDisp, const RowPaths &paths, const uint8_t *grey,
             const uint8_t *greyPrev, const PathParams &pp, uint16_t *sum, bool initSum) {
    if (paths.count == 1 && !sum) {
        switch (paddedDisp / kLanes8) {
        case 1: return onePathOf<1>(cost, width, paths, grey, greyPrev, pp);
        case 2: return onePathOf<2>(cost, width, paths, grey, greyPrev, pp);
        case 4: return onePathOf<4>(cost, width, paths, grey, greyPrev, pp);
        case 8: return onePathOf<8>(cost, width, paths, grey, greyPrev, pp);
        default: break;
        }
    }
    if (paths.count == 1) pathRowOf<1>(cost, width, paddedDisp, paths, grey, greyPrev, pp, sum, initSum);
    else if (paths.count == 2) pathRowOf<2>(cost, width, paddedDisp, paths, grey, greyPrev, pp, sum, initSum);
    else pathRowOf<kMaxRowPaths>(cost, width, paddedDisp, paths, grey, greyPrev, pp, sum, initSum);
}

// Both horizontal paths of a row, left to right and right to left, interleaved: each is
// a serial chain (a pixel needs its predecessor's minimum), so running the two side by
// side lets the CPU overlap their latencies. Each carries its previous pixel's costs in
// whole vectors (the d - 1 and d + 1 neighbours by lane shifts, not by loads at +-1
// byte, which would stall on store forwarding at every pixel).
struct HorizontalChain {
    static constexpr int kMaxChunks = kMaxPaddedDisp / kLanes8;
    v_uint8 bufA[kMaxChunks], bufB[kMaxChunks];
    v_uint8 *prev = bufA, *cur = bufB;
    int minPrev = 255, previousX = -1;

    // path: where the pixel's path costs go (the cost-row layout), instead of into sum.
    void step(const uint8_t *cost, int chunks, int paddedDisp, int x, const uint8_t *grey, const PathParams &pp,
              const v_uint8 &p1, uint16_t *sum, bool initSum, uint8_t *path) {
        const v_uint8 invalid = vx_setall_u8(kCostInvalid);
        if (previousX < 0)
            for (int c = 0; c < chunks; ++c) prev[c] = invalid;
        // The first pixel's P2 does not matter (previous costs and minimum 255, jump 255).
        const int p2 = pp.p2ByStep[grey[x] - grey[previousX < 0 ? x : previousX]];
        const v_uint8 base = vx_setall_u8(static_cast<uint8_t>(minPrev));
        const v_uint8 jump = base + vx_setall_u8(static_cast<uint8_t>(p2));
        const uint8_t *c0 = cost + static_cast<size_t>(x) * paddedDisp;
        uint16_t *s0 = path ? nullptr : sum + static_cast<size_t>(x) * paddedDisp;
        v_uint8 least = invalid;
        for (int c = 0; c < chunks; ++c) {
            const v_uint8 below = v_extract<kLanes8 - 1>(c > 0 ? prev[c - 1] : invalid, prev[c]); // d - 1
            const v_uint8 above = v_extract<1>(prev[c], c + 1 < chunks ? prev[c + 1] : invalid);  // d + 1
            const v_uint8 t = v_min(v_min(prev[c], v_min(below, above) + p1), jump);
            const v_uint8 l = vx_load(c0 + c * kLanes8) + (t - base);
            cur[c] = l;
            least = v_min(least, l);
            if (path) {
                v_store(path + static_cast<size_t>(x) * paddedDisp + c * kLanes8, l);
                continue;
            }
            v_uint16 lo, hi;
            v_expand(l, lo, hi);
            uint16_t *s = s0 + c * kLanes8;
            if (initSum) {
                v_store(s, lo);
                v_store(s + kLanes16, hi);
            } else {
                v_store(s, vx_load(s) + lo);
                v_store(s + kLanes16, vx_load(s + kLanes16) + hi);
            }
        }
        minPrev = leastByte(least);
        std::swap(prev, cur);
        previousX = x;
    }
};

// The same chain with its previous pixel's costs in registers: the number of vectors per
// pixel is a template argument (1 .. 8), so the loops unroll and nothing goes through
// memory between two pixels of the chain.
template <int Chunks>
struct RegisterChain {
    v_uint8 prev[Chunks];
    v_uint8 base; // the previous pixel's least cost, in every lane

    RegisterChain() {
        for (auto &v : prev) v = vx_setall_u8(kCostInvalid);
        base = vx_setall_u8(kCostInvalid);
    }
    // p2: P2 between x and the previous pixel (any value for the first: its previous costs
    // and minimum are 255, so is the jump). Paths: the pixel's path costs stored to path
    // (the cost-row layout), else added to sum (stored, when initSum).
    template <bool Paths>
    inline __attribute__((always_inline)) void step(const uint8_t *cost, int paddedDisp, int x, int p2,
                                                    const v_uint8 &p1, uint16_t *sum, bool initSum, uint8_t *path) {
        const v_uint8 invalid = vx_setall_u8(kCostInvalid);
        const v_uint8 jump = base + vx_setall_u8(static_cast<uint8_t>(p2));
        const uint8_t *c0 = cost + static_cast<size_t>(x) * paddedDisp;
        v_uint8 cur[Chunks];
        v_uint8 least = invalid;
#pragma GCC unroll 8
        for (int c = 0; c < Chunks; ++c) {
            const v_uint8 below = v_extract<kLanes8 - 1>(c > 0 ? prev[c - 1] : invalid, prev[c]); // d - 1
            const v_uint8 above = v_extract<1>(prev[c], c + 1 < Chunks ? prev[c + 1] : invalid);  // d + 1
            const v_uint8 t = v_min(v_min(prev[c], v_min(below, above) + p1), jump);
            cur[c] = vx_load(c0 + c * kLanes8) + (t - base);
            least = v_min(least, cur[c]);
        }
        base = leastByteEverywhere(least);
        if constexpr (Paths) {
#pragma GCC unroll 8
            for (int c = 0; c < Chunks; ++c) {
                prev[c] = cur[c];
                v_store(path + static_cast<size_t>(x) * paddedDisp + c * kLanes8, cur[c]);
            }
            return;
        }
        uint16_t *s0 = sum + static_cast<size_t>(x) * paddedDisp;
#pragma GCC unroll 8
        for (int c = 0; c < Chunks; ++c) {
            prev[c] = cur[c];
            v_uint16 lo, hi;
            v_expand(cur[c], lo, hi);
            uint16_t *s = s0 + c * kLanes8;
            if (initSum) {
                v_store(s, lo);
                v_store(s + kLanes16, hi);
            } else {
                v_store(s, vx_load(s) + lo);
                v_store(s + kLanes16, vx_load(s + kLanes16) + hi);
            }
        }
    }
};

// Rows rows (1 or 2), each with both chains, all side by side. Paths: each chain's path
// costs stored whole (forward[r], backward[r]); else both added to sum[r] (stored, when
// initSum). p2Rows: scratch of Rows * (width + 1) bytes for the P2 of each pixel and its
// left neighbour, looked up once per row for both directions: p2Of[r][x] for the pair
// x - 1, x.
struct HorizontalOut {
    uint16_t *const *sum;
    bool initSum;
    uint8_t *const *forward, *const *backward; // Paths
};

template <int Chunks, int Rows, bool Paths>
void horizontalOf(const uint8_t *const *cost, int width, int paddedDisp, const uint8_t *const *grey,
                  const PathParams &pp, uint8_t *p2Rows, const HorizontalOut &to) {
    const v_uint8 p1 = vx_setall_u8(static_cast<uint8_t>(pp.p1));
    const uint8_t *rowCost[Rows], *p2Of[Rows];
    uint16_t *rowSum[Rows] = {};
    uint8_t *rowForward[Rows] = {}, *rowBackward[Rows] = {};
    for (int r = 0; r < Rows; ++r) {
        rowCost[r] = cost[r];
        if constexpr (Paths) {
            rowForward[r] = to.forward[r];
            rowBackward[r] = to.backward[r];
        } else {
            rowSum[r] = to.sum[r];
        }
        uint8_t *p2 = p2Rows + r * (static_cast<size_t>(width) + 1);
        const uint8_t *g = grey[r];
        p2[0] = p2[width] = pp.p2ByStep[0]; // the first pixel of each direction: any value
        for (int x = 1; x < width; ++x) p2[x] = pp.p2ByStep[g[x] - g[x - 1]];
        p2Of[r] = p2;
    }
    const bool initSum = to.initSum;
    RegisterChain<Chunks> forward[Rows], backward[Rows];
    for (int i = 0; i < width; ++i) {
        const int xb = width - 1 - i;
        // Sums are exact (at most 8 x 255), so the order of the additions does not
        // matter; the first path to reach a pixel stores instead of adding.
#pragma GCC unroll 2
        for (int r = 0; r < Rows; ++r)
            forward[r].template step<Paths>(rowCost[r], paddedDisp, i, p2Of[r][i], p1, rowSum[r], initSum && i <= xb,
                                            rowForward[r]);
#pragma GCC unroll 2
        for (int r = 0; r < Rows; ++r)
            backward[r].template step<Paths>(rowCost[r], paddedDisp, xb, p2Of[r][xb + 1], p1, rowSum[r],
                                             initSum && xb > i, rowBackward[r]);
    }
}

// The generic chain, for more than 8 vectors per pixel (SSE2 / NEON with 256 disparities).
template <int Rows>
void horizontalAny(const uint8_t *const *cost, int width, int paddedDisp, const uint8_t *const *grey,
                   const PathParams &pp, const HorizontalOut &to) {
    const int chunks = paddedDisp / kLanes8;
    const v_uint8 p1 = vx_setall_u8(static_cast<uint8_t>(pp.p1));
    HorizontalChain forward[Rows], backward[Rows];
    for (int i = 0; i < width; ++i) {
        const int xb = width - 1 - i;
        for (int r = 0; r < Rows; ++r)
            forward[r].step(cost[r], chunks, paddedDisp, i, grey[r], pp, p1, to.sum ? to.sum[r] : nullptr,
                            to.initSum && i <= xb, to.forward ? to.forward[r] : nullptr);
        for (int r = 0; r < Rows; ++r)
            backward[r].step(cost[r], chunks, paddedDisp, xb, grey[r], pp, p1, to.sum ? to.sum[r] : nullptr,
                             to.initSum && xb > i, to.backward ? to.backward[r] : nullptr);
    }
}

template <int Rows, bool Paths>
void horizontal(const uint8_t *const *cost, int width, int paddedDisp, const uint8_t *const *grey, const PathParams &pp,
                uint8_t *scratch, const HorizontalOut &to) {
    uint8_t *p2Rows = scratch + 2 * pathStride(paddedDisp);
    switch (paddedDisp / kLanes8) {
#define SGM_HORIZONTAL(n) \
    case n: return horizontalOf<n, Rows, Paths>(cost, width, paddedDisp, grey, pp, p2Rows, to);
        SGM_HORIZONTAL(1) SGM_HORIZONTAL(2) SGM_HORIZONTAL(3) SGM_HORIZONTAL(4)
        SGM_HORIZONTAL(5) SGM_HORIZONTAL(6) SGM_HORIZONTAL(7) SGM_HORIZONTAL(8)
#undef SGM_HORIZONTAL
    default: return horizontalAny<Rows>(cost, width, paddedDisp, grey, pp, to);
    }
}

void horizontalRow(const uint8_t *cost, int width, int paddedDisp, const uint8_t *grey, const PathParams &pp,
                   uint8_t *scratch, uint16_t *sum, bool initSum) {
    horizontal<1, false>(&cost, width, paddedDisp, &grey, pp, scratch, HorizontalOut{&sum, initSum, nullptr, nullptr});
}

void horizontalPaths(const uint8_t *const *cost, int rows, int width, int paddedDisp, const uint8_t *const *grey,
                     const PathParams &pp, uint8_t *scratch, uint8_t *const *forward, uint8_t *const *backward) {
    const HorizontalOut to{nullptr, false, forward, backward};
    if (rows == 2) horizontal<2, true>(cost, width, paddedDisp, grey, pp, scratch, to);
    else horizontal<1, true>(cost, width, paddedDisp, grey, pp, scratch, to);
}

void addPathRow(const uint8_t *pathRow, int width, int paddedDisp, uint16_t *sum) {
    const int stride = pathStride(paddedDisp);
    for (int x = 0; x < width; ++x) {
        const uint8_t *l0 = pathRow + static_cast<size_t>(x) * stride + 1;
        uint16_t *s0 = sum + static_cast<size_t>(x) * paddedDisp;
        for (int d = 0; d < paddedDisp; d += kLanes8) {
            v_store(s0 + d, vx_load(s0 + d) + vx_load_expand(l0 + d));
            v_store(s0 + d + kLanes16, vx_load(s0 + d + kLanes16) + vx_load_expand(l0 + d + kLanes16));
        }
    }
}

// Winner takes all, and the fused pass up of 4 paths that ends in it.
#include "sgm_kernels_simd_wta.inl"
// The median filter on the disparity.
#include "sgm_kernels_simd_median.inl"

} // namespace

const Kernels &table(const char *name) {
    static const Kernels k{name, kTableDispAlign, censusRow, costScratch, costRow, costRow32, pathRow, horizontalRow, horizontalPaths, addPathRow, wtaRow, upWtaRow, leftRightRow, medianRow};
    return k;
}

} // namespace SGM_SIMD_NS
} // namespace sgm

#endif // CV_SIMD
