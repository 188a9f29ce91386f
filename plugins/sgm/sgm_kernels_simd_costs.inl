// SPDX-License-Identifier: MIT
// sgm: the SIMD matching costs of a row: Hamming distances of census words
// (64-bit words, and words of at most 32 bits on 32-bit lanes). A part of
// sgm_kernels_simd.inl, included by it inside its namespaces: not a header of its own.
#ifndef SGM_SIMD_NS
#error "sgm_kernels_simd_costs.inl is included by sgm_kernels_simd.inl only"
#endif

// ---- costs ----------------------------------------------------------------------------
// Bits set in each 64-bit lane. OpenCV's 256-bit v_popcount takes two byte-table lookups
// and a sum of absolute differences; AVX-512 VPOPCNTDQ counts them in one instruction.
inline v_uint64 popcount64(const v_uint64 &a) {
#if CV_SIMD_WIDTH == 64 && CV_AVX_512VPOPCNTDQ
    return v_uint64(_mm512_popcnt_epi64(a.val));
#else
    return v_popcount(a);
#endif
}

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
