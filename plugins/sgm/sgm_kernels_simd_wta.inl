// SPDX-License-Identifier: MIT
// sgm: the SIMD kernels of winner takes all and the fused pass up of 4 paths (which ends
// in winner takes all). A part of sgm_kernels_simd.inl, included by it inside its
// namespaces, after the path kernels: not a header of its own.
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

// ---- the winner of 4 paths, by keys --------------------------------------------------
// A sum of 4 paths is at most kMaxSum4 (10 bits): key = sum << 6 | d mod 64 fits 16 bits,
// and the least key of a group of 64 disparities is its least sum and the lowest d that
// holds it, in one minimum. Lanes d >= numDisp hold 0xFFFF, above every key.
constexpr int kKeyGroup = 1 << kWinnerKeyShift;
// How far ahead the fused pass up asks for its inputs (measured: 3 pixels too few, 6 to
// 12 alike at 640 x 480 x 128).
constexpr int kPrefetchPixels = 8;
constexpr int kMaxKeyGroups = kMaxPaddedDisp / kKeyGroup;

// The uniqueness test by keys: a rival d (|d - b| > 1) fails it when s * (100 - u) < m *
// 100, that is when s < T(m) = ceil(m * 100 / (100 - u)), that is when its key is below
// T(m) << 6. keysBelow(u)[m]: that bound (T capped at kMaxSum4 + 1, which every key of a
// real candidate is below and 0xFFFF is not). One table per thread, made again only when
// u changes.
const uint16_t *keysBelow(int uniquenessPercent) {
    thread_local int made = -1;
    thread_local uint16_t below[kMaxSum4 + 1];
    if (made != uniquenessPercent) {
        const int keep = 100 - uniquenessPercent;
        for (int m = 0; m <= kMaxSum4; ++m)
            below[m] = static_cast<uint16_t>(std::min((m * 100 + keep - 1) / keep, kMaxSum4 + 1) << kWinnerKeyShift);
        made = uniquenessPercent;
    }
    return below;
}

#if CV_SIMD_WIDTH == 64
// AVX-512: the lanes a winner b leaves to its rivals (|d - b| > 1) as mask registers, one
// 32-bit word per vector of 16-bit lanes: allowedLanes()[b * kWords + i].
constexpr int kLaneWords = kMaxPaddedDisp / kLanes16;
struct AllowedLanes {
    uint32_t bits[kMaxPaddedDisp * kLaneWords];
    AllowedLanes() {
        for (int b = 0; b < kMaxPaddedDisp; ++b)
            for (int d = 0; d < kMaxPaddedDisp; ++d) {
                uint32_t &word = bits[b * kLaneWords + d / kLanes16];
                if (d % kLanes16 == 0) word = 0;
                if (std::abs(d - b) > 1) word |= 1u << (d % kLanes16);
            }
    }
};
const uint32_t *allowedLanes() {
    static const AllowedLanes lanes;
    return lanes.bits;
}
#endif

// The pass up of 4 paths, fused (sgm_kernels.hpp): per pixel the vertical path from
// below, the sums of the four paths as keys in a buffer that stays in L1 (nothing 16-bit
// is stored to the row), the least key of each group on the way, then the winner.
// Chunks: vectors per pixel (paddedDisp / kLanes8) when known at compile time (the loop
// over the disparities unrolls), 0 when not.
template <int Chunks>
void upWtaOf(const uint8_t *cost, int width, int runtimePaddedDisp, const RowPaths &paths, const uint8_t *grey,
             const uint8_t *greyPrev, const PathParams &pp, const uint8_t *keptPath, const uint8_t *forward,
             const uint8_t *backward, const WtaParams &wp, int16_t *best, uint16_t *bestSum, uint16_t *disparity16) {
    const int paddedDisp = Chunks > 0 ? Chunks * kLanes8 : runtimePaddedDisp;
    const int stride = pathStride(paddedDisp);
    const int groups = (paddedDisp + kKeyGroup - 1) / kKeyGroup;
    const v_uint8 p1 = vx_setall_u8(static_cast<uint8_t>(pp.p1));
    // Local copies: the stores through uint8_t pointers below may alias anything, so the
    // compiler would otherwise load every field again at each pixel.
    const uint8_t *const prevL = paths.prevL[0], *const prevMin = paths.prevMin[0], *const lut = pp.p2ByStep;
    uint8_t *const curL = paths.curL[0], *const curMin = paths.curMin[0];
    const WtaParams w = wp;
    // The low bits of each lane's key: d mod 64, or 0xFFFF for d >= numDisp.
    alignas(64) uint16_t laneKey[kMaxPaddedDisp];
    for (int d = 0; d < paddedDisp; ++d) laneKey[d] = d < w.numDisp ? static_cast<uint16_t>(d % kKeyGroup) : 0xFFFF;
    const uint16_t *const below = keysBelow(w.uniquenessPercent);
#if CV_SIMD_WIDTH == 64
    const uint32_t *const allowed = allowedLanes();
#else
    const uint16_t *const laneD = laneDisparities();
#endif
    // The keys of a batch of pixels first, then their winners: a winner is a chain of
    // dependent steps (least key, uniqueness, parabola), and the chains of neighbouring
    // pixels, side by side in the instruction stream, overlap.
    constexpr int kBatch = 8;
    alignas(64) uint16_t keys[kBatch][kMaxPaddedDisp];
    int winner[kBatch], leastSum[kBatch];
    for (int x0 = 0; x0 < width; x0 += kBatch) {
        const int n = std::min(kBatch, width - x0);
        for (int j = 0; j < n; ++j) {
            const int x = x0 + j;
            uint16_t *key = keys[j];
            const bool has = prevL != nullptr;
            const uint8_t *prev = has ? prevL + static_cast<size_t>(x) * stride + 1 : freshPath();
            const int minPrev = has ? prevMin[x] : 255;
            const int p2 = has ? lut[grey[x] - greyPrev[x]] : lut[0];
            const v_uint8 base = vx_setall_u8(static_cast<uint8_t>(minPrev));
            const v_uint8 jump = base + vx_setall_u8(static_cast<uint8_t>(p2));
            v_uint8 least = vx_setall_u8(255);
            v_uint16 groupLeast[kMaxKeyGroups];
            for (v_uint16 &g : groupLeast) g = vx_setall_u16(0xFFFF);
            uint8_t *out = curL + static_cast<size_t>(x) * stride + 1;
            const uint8_t *c0 = cost + static_cast<size_t>(x) * paddedDisp;
            const uint8_t *k0 = keptPath + static_cast<size_t>(x) * stride + 1;
            const uint8_t *f0 = forward + static_cast<size_t>(x) * paddedDisp;
            const uint8_t *b0 = backward + static_cast<size_t>(x) * paddedDisp;
            // The streams of a pixel kPrefetchPixels on asked for now: the kept path and the
            // costs come from memory (the pass down wrote them long before), the horizontal
            // paths from L2, and the hardware prefetcher, following a dozen streams, falls
            // behind.
            for (int d = 0; d < paddedDisp; d += 64) {
                __builtin_prefetch(c0 + kPrefetchPixels * paddedDisp + d);
                __builtin_prefetch(k0 + kPrefetchPixels * stride + d);
                __builtin_prefetch(f0 + kPrefetchPixels * paddedDisp + d);
                __builtin_prefetch(b0 + kPrefetchPixels * paddedDisp + d);
            }
#pragma GCC unroll 8
            for (int d = 0; d < paddedDisp; d += kLanes8) {
                const uint8_t *q = prev + d;
                const v_uint8 steps = v_min(vx_load(q - 1), vx_load(q + 1)) + p1;
                const v_uint8 l = vx_load(c0 + d) + (v_min(v_min(vx_load(q), steps), jump) - base);
                v_store(out + d, l);
                least = v_min(least, l);
                v_uint16 l0, l1;
                v_expand(l, l0, l1);
                // The stored paths widened as they are loaded (not loaded whole, then split:
                // with 512-bit vectors GCC splits them through the stack).
                const v_uint16 lo = vx_load_expand(f0 + d) + vx_load_expand(b0 + d) + l0 + vx_load_expand(k0 + d);
                const v_uint16 hi = vx_load_expand(f0 + d + kLanes16) + vx_load_expand(b0 + d + kLanes16) + l1 +
                                    vx_load_expand(k0 + d + kLanes16);
                const v_uint16 keyLo = v_shl<kWinnerKeyShift>(lo) | vx_load_aligned(laneKey + d);
                const v_uint16 keyHi = v_shl<kWinnerKeyShift>(hi) | vx_load_aligned(laneKey + d + kLanes16);
                v_store_aligned(key + d, keyLo);
                v_store_aligned(key + d + kLanes16, keyHi);
                v_uint16 &group = groupLeast[d / kKeyGroup];
                group = v_min(group, v_min(keyLo, keyHi));
            }
            curMin[x] = leastByte(least);
            // The least sum over the groups, the first group on a tie: the lowest d.
            int leastKey = leastWord(groupLeast[0]), leastGroup = 0;
            for (int g = 1; g < groups; ++g) {
                const int k = leastWord(groupLeast[g]);
                const bool less = k >> kWinnerKeyShift < leastKey >> kWinnerKeyShift;
                leastKey = less ? k : leastKey;
                leastGroup = less ? g : leastGroup;
            }
            leastSum[j] = leastKey >> kWinnerKeyShift;
            winner[j] = leastGroup * kKeyGroup + (leastKey & (kKeyGroup - 1));
        }
        for (int j = 0; j < n; ++j) {
            const int x = x0 + j, b = winner[j], m = leastSum[j];
            bestSum[x] = static_cast<uint16_t>(m);
            if (x - w.minDisparity - b < 0) {
                best[x] = -1;
                disparity16[x] = 0;
                continue;
            }
            best[x] = static_cast<int16_t>(b);
            const uint16_t *key = keys[j];
            const v_uint16 bound = vx_setall_u16(below[m]);
#if CV_SIMD_WIDTH == 64
            // A rival below the bound, among the lanes b leaves to its rivals.
            __mmask32 rivals = 0;
            const uint32_t *lanes = allowed + b * kLaneWords;
#pragma GCC unroll 16
            for (int d = 0, i = 0; d < paddedDisp; d += kLanes16, ++i)
                rivals |= _mm512_mask_cmplt_epu16_mask(lanes[i], vx_load_aligned(key + d).val, bound.val);
            const bool unique = rivals == 0;
#else
            // d - (b - 1), wrapped, is at most 2 exactly for b - 1, b, b + 1: not rivals.
            const v_uint16 lowest = vx_setall_u16(static_cast<uint16_t>(b - 1)), two = vx_setall_u16(2);
            v_uint16 rivals = vx_setzero_u16();
#pragma GCC unroll 16
            for (int d = 0; d < paddedDisp; d += kLanes16) {
                const v_uint16 offset = v_sub_wrap(vx_load(laneD + d), lowest);
                rivals = rivals | ((vx_load_aligned(key + d) < bound) & ~(v_min(offset, two) == offset));
            }
            const bool unique = !v_check_any(rivals);
#endif
            const bool inner = b > 0 && b < w.numDisp - 1;
            disparity16[x] = unique ? refinedDisparity16(inner ? key[b - 1] >> kWinnerKeyShift : 0, m,
                                                         inner ? key[b + 1] >> kWinnerKeyShift : 0, b, w)
                                    : 0;
        }
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

void upWtaRow(const uint8_t *cost, int width, int paddedDisp, const RowPaths &paths, const uint8_t *grey,
              const uint8_t *greyPrev, const PathParams &pp, const uint8_t *keptPath, const uint8_t *forward,
              const uint8_t *backward, const WtaParams &wp, int16_t *best, uint16_t *bestSum, uint16_t *disparity16) {
    switch (paddedDisp / kLanes8) {
    // Only the counts of vectors a padded count (at most kMaxPaddedDisp) can have.
#define SGM_UP_WTA(n) \
    case n: \
        if constexpr (n * kLanes8 <= kMaxPaddedDisp) \
            return upWtaOf<n>(cost, width, paddedDisp, paths, grey, greyPrev, pp, keptPath, forward, backward, wp, best, \
                              bestSum, disparity16); \
        break;
        SGM_UP_WTA(1) SGM_UP_WTA(2) SGM_UP_WTA(4) SGM_UP_WTA(8)
#undef SGM_UP_WTA
    default:
        return upWtaOf<0>(cost, width, paddedDisp, paths, grey, greyPrev, pp, keptPath, forward, backward, wp, best,
                          bestSum, disparity16);
    }
}
