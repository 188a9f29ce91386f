// SPDX-License-Identifier: MIT
// sgm: the SIMD kernels of winner takes all and of the left-right check. A part of
// sgm_kernels_simd.inl, included by it inside its namespaces, after the path kernels: not
// a header of its own.
#ifndef SGM_SIMD_NS
#error "sgm_kernels_simd_wta.inl is included by sgm_kernels_simd.inl only"
#endif

// ---- winner takes all -----------------------------------------------------------------
// d of each 16-bit lane of the vectors of a pixel's sums, for the masks of the uniqueness
// test (a vector per kLanes16 disparities, up to 256).
struct LaneDisparities {
    alignas(64) uint16_t d[kMaxPaddedDisp];
    LaneDisparities() {
        for (int i = 0; i < kMaxPaddedDisp; ++i) d[i] = static_cast<uint16_t>(i);
    }
};
const uint16_t *laneDisparities() {
    static const LaneDisparities lanes;
    return lanes.d;
}

// One pixel's winner takes all, its least sum m already known. The uniqueness test
// (OpenCV's: not unique when some d with |d - b| > 1 has s[d] * (100 - u) < m * 100) by
// the least sum away from b, m2: not unique exactly when m2 * (100 - u) < m * 100 (no
// count, no division, no correction for b - 1, b, b + 1: they are masked out).
// Vectors > 0: s holds that many vectors of sums, those at d >= numDisp 0xFFFF (never the
// least, never below it): the loops have a constant trip count and unroll; 0: the
// numDisp sums only, their count known at run time.
template <int Vectors>
inline __attribute__((always_inline)) void wtaPixel(const uint16_t *s, int m, int x, const WtaParams &wp,
                                                    const uint16_t *laneD, int16_t *best, uint16_t *bestSum,
                                                    uint16_t *disparity16) {
    const int whole = Vectors > 0 ? Vectors * kLanes16 : wp.numDisp / kLanes16 * kLanes16;
    const int tail = Vectors > 0 ? whole : wp.numDisp;
    const v_uint16 vm = vx_setall_u16(static_cast<uint16_t>(m));
    int b = -1;
    // The lowest d holding the least sum, backwards, without a branch on where it lies (it
    // is anywhere: a branch would be mispredicted at every other pixel): the last kept.
#pragma GCC unroll 16
    for (int d = whole - kLanes16; d >= 0; d -= kLanes16) {
#if CV_SIMD_WIDTH == 64
        // AVX-512 compares into a mask register: a bit a lane.
        const uint32_t eq = _mm512_cmpeq_epi16_mask(vx_load(s + d).val, vm.val);
        b = eq != 0 ? d + __builtin_ctz(eq) : b;
#else
        // The byte mask of the 16-bit comparison (two bits a lane): one instruction, where
        // the 16-bit mask takes a pack and a permute first.
        const uint64_t eq = static_cast<uint32_t>(v_signmask(v_reinterpret_as_u8(vx_load(s + d) == vm)));
        b = eq != 0 ? d + __builtin_ctzll(eq) / 2 : b;
#endif
    }
    for (int d = whole; d < tail; ++d)
        if (b < 0 && s[d] == m) b = d;
    bestSum[x] = static_cast<uint16_t>(m);
    if (x - wp.minDisparity - b < 0) {
        best[x] = -1;
        disparity16[x] = 0;
        return;
    }
    best[x] = static_cast<int16_t>(b);
    // d - (b - 1), wrapped, is at most 2 exactly for b - 1, b, b + 1: those lanes become
    // 0xFFFF (OR with the all-ones mask) before the minimum.
    const v_uint16 lowest = vx_setall_u16(static_cast<uint16_t>(b - 1)), two = vx_setall_u16(2);
    v_uint16 away = vx_setall_u16(0xFFFF);
#pragma GCC unroll 16
    for (int d = 0; d < whole; d += kLanes16) {
        const v_uint16 offset = v_sub_wrap(vx_load(laneD + d), lowest);
        away = v_min(away, vx_load(s + d) | v_reinterpret_as_u16(v_min(offset, two) == offset));
    }
    int m2 = leastWord(away);
    for (int d = whole; d < tail; ++d)
        if (std::abs(d - b) > 1) m2 = std::min<int>(m2, s[d]);
    disparity16[x] = m2 * (100 - wp.uniquenessPercent) >= m * 100 ? refinedDisparity16(s, b, wp) : 0;
}

void wtaRow(const uint16_t *sum, int width, const WtaParams &wp, int16_t *best, uint16_t *bestSum,
            uint16_t *disparity16) {
    const int whole = wp.numDisp / kLanes16 * kLanes16;
    const uint16_t *laneD = laneDisparities();
    for (int x = 0; x < width; ++x) {
        const uint16_t *s = sum + static_cast<size_t>(x) * wp.paddedDisp;
        v_uint16 least = vx_setall_u16(0xFFFF);
        for (int d = 0; d < whole; d += kLanes16) least = v_min(least, vx_load(s + d));
        int m = leastWord(least);
        for (int d = whole; d < wp.numDisp; ++d) m = std::min<int>(m, s[d]);
        wtaPixel<0>(s, m, x, wp, laneD, best, bestSum, disparity16);
    }
}

// ---- the left-right check ----------------------------------------------------------
// The keys of the right columns as every table makes them (rightColumnKeys), then the
// check of kLanes32 pixels at once, their right columns' keys gathered.
void leftRightRow(const int16_t *best, const uint16_t *bestSum, int width, int minD, int maxDiff, uint32_t *rightKey,
                  uint16_t *disparity16) {
    constexpr int kLanes32 = v_int32::nlanes;
    rightColumnKeys(best, bestSum, width, minD, rightKey);
    alignas(64) int32_t lane[kLanes32];
    for (int i = 0; i < kLanes32; ++i) lane[i] = i;
    const v_int32 iota = vx_load_aligned(lane), spare = vx_setall_s32(width), zero = vx_setzero_s32();
    const v_int32 low = vx_setall_s32(0xFFFF), most = vx_setall_s32(maxDiff);
    const int *keys = reinterpret_cast<const int *>(rightKey);
    int x = 0;
    for (; x + kLanes32 <= width; x += kLanes32) {
        const v_int32 d = vx_load_expand(best + x);
        const v_int32 none = d < zero;
        const v_int32 column = v_select(none, spare, vx_setall_s32(x - minD) + iota - d);
        const v_int32 rightD = v_lut(keys, column) & low;
        const v_int32 mismatch = v_reinterpret_as_s32(v_abs(rightD - d)) > most;
        const v_uint32 kept = v_reinterpret_as_u32(~(mismatch & ~none));
        v_pack_store(disparity16 + x, vx_load_expand(disparity16 + x) & kept);
    }
    for (; x < width; ++x) {
        const int d = best[x];
        const int rightD = static_cast<int>(rightKey[d < 0 ? width : x - minD - d] & 0xFFFF);
        disparity16[x] = d < 0 || std::abs(rightD - d) <= maxDiff ? disparity16[x] : 0;
    }
}
