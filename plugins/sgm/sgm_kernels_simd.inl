// SPDX-License-Identifier: MIT
// sgm: the SIMD kernels, written once with OpenCV's universal intrinsics and compiled
// once per instruction set (sgm_kernels_baseline.cpp, sgm_kernels_avx2.cpp,
// sgm_kernels_avx512.cpp: 16-, 32- and 64-byte vectors). The
// including file defines SGM_SIMD_NS, a namespace of its own: the same inline code
// compiled with other flags must not be merged by the linker.
//
// What each kernel computes is stated by its scalar reference (sgm_kernels_scalar.cpp).
// One file per stage, included below: census, costs, paths (from the previous row, and
// horizontal), winner takes all with the left-right check, the fused pass up, median;
// this file holds what they share and the table.
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

// The path that starts at a row (no predecessor): every cost 255.
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

// The stages, in the order a pair goes through them (as libSGM splits them).
#include "sgm_kernels_simd_census.inl"
#include "sgm_kernels_simd_costs.inl"
#include "sgm_kernels_simd_paths.inl"
#include "sgm_kernels_simd_horizontal.inl"
// Winner takes all and the left-right check; the fused pass up of 4 paths that ends in
// the winner.
#include "sgm_kernels_simd_wta.inl"
#include "sgm_kernels_simd_up_wta.inl"
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
