// SPDX-License-Identifier: MIT
// sgm: the SIMD fused pass up of 4 paths, which ends in winner takes all (by 16-bit
// keys). A part of sgm_kernels_simd.inl, included by it inside its namespaces, after
// winner takes all: not a header of its own.
#ifndef SGM_SIMD_NS
#error "sgm_kernels_simd_up_wta.inl is included by sgm_kernels_simd.inl only"
#endif

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

// One row of the fused pass up: what it reads and writes, and its constants. Local
// copies of the caller's fields: the stores through uint8_t pointers below may alias
// anything, so the compiler would otherwise load every field again at each pixel.
struct UpRow {
    const uint8_t *prevL, *prevMin, *lut, *grey, *greyPrev;
    const uint8_t *cost, *keptPath, *forward, *backward;
    uint8_t *curL, *curMin;
    int16_t *best;
    uint16_t *bestSum, *disparity16;
    int paddedDisp;
    WtaParams w;
    const uint16_t *laneKey; // the low bits of each lane's key: d mod 64, or 0xFFFF for d >= numDisp
    const uint16_t *below;   // keysBelow(w.uniquenessPercent)
#if CV_SIMD_WIDTH == 64
    const uint32_t *allowed; // allowedLanes()
#else
    const uint16_t *laneD; // laneDisparities()
#endif
};

// Pixel x: its vertical path from below (stored, and its minimum), the sums of the four
// paths as keys (key), the least key of each group on the way. Returns its least sum and
// the lowest d that holds it (winner).
template <int Chunks>
inline __attribute__((always_inline)) int upKeysOf(const UpRow &r, const v_uint8 &p1, int x, uint16_t *key,
                                                   int &winner) {
    const int paddedDisp = Chunks > 0 ? Chunks * kLanes8 : r.paddedDisp;
    const int stride = pathStride(paddedDisp);
    const int groups = (paddedDisp + kKeyGroup - 1) / kKeyGroup;
    const bool has = r.prevL != nullptr;
    const uint8_t *prev = has ? r.prevL + static_cast<size_t>(x) * stride + 1 : freshPath();
    const int minPrev = has ? r.prevMin[x] : 255;
    const int p2 = has ? r.lut[r.grey[x] - r.greyPrev[x]] : r.lut[0];
    const v_uint8 base = vx_setall_u8(static_cast<uint8_t>(minPrev));
    const v_uint8 jump = base + vx_setall_u8(static_cast<uint8_t>(p2));
    v_uint8 least = vx_setall_u8(255);
    v_uint16 groupLeast[kMaxKeyGroups];
    for (v_uint16 &g : groupLeast) g = vx_setall_u16(0xFFFF);
    uint8_t *out = r.curL + static_cast<size_t>(x) * stride + 1;
    const uint8_t *c0 = r.cost + static_cast<size_t>(x) * paddedDisp;
    const uint8_t *k0 = r.keptPath + static_cast<size_t>(x) * stride + 1;
    const uint8_t *f0 = r.forward + static_cast<size_t>(x) * paddedDisp;
    const uint8_t *b0 = r.backward + static_cast<size_t>(x) * paddedDisp;
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
        const v_uint16 keyLo = v_shl<kWinnerKeyShift>(lo) | vx_load_aligned(r.laneKey + d);
        const v_uint16 keyHi = v_shl<kWinnerKeyShift>(hi) | vx_load_aligned(r.laneKey + d + kLanes16);
        v_store_aligned(key + d, keyLo);
        v_store_aligned(key + d + kLanes16, keyHi);
        v_uint16 &group = groupLeast[d / kKeyGroup];
        group = v_min(group, v_min(keyLo, keyHi));
    }
    r.curMin[x] = leastByte(least);
    // The least sum over the groups, the first group on a tie: the lowest d.
    int leastKey = leastWord(groupLeast[0]), leastGroup = 0;
    for (int g = 1; g < groups; ++g) {
        const int k = leastWord(groupLeast[g]);
        const bool less = k >> kWinnerKeyShift < leastKey >> kWinnerKeyShift;
        leastKey = less ? k : leastKey;
        leastGroup = less ? g : leastGroup;
    }
    winner = leastGroup * kKeyGroup + (leastKey & (kKeyGroup - 1));
    return leastKey >> kWinnerKeyShift;
}

// Pixel x's winner b (least sum m) from its keys: none without a candidate; else the
// uniqueness test by keys, then the parabola.
template <int Chunks>
inline __attribute__((always_inline)) void upWinnerOf(const UpRow &r, int x, const uint16_t *key, int b, int m) {
    const int paddedDisp = Chunks > 0 ? Chunks * kLanes8 : r.paddedDisp;
    r.bestSum[x] = static_cast<uint16_t>(m);
    if (x - r.w.minDisparity - b < 0) {
        r.best[x] = -1;
        r.disparity16[x] = 0;
        return;
    }
    r.best[x] = static_cast<int16_t>(b);
    const v_uint16 bound = vx_setall_u16(r.below[m]);
#if CV_SIMD_WIDTH == 64
    // A rival below the bound, among the lanes b leaves to its rivals.
    __mmask32 rivals = 0;
    const uint32_t *lanes = r.allowed + b * kLaneWords;
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
        const v_uint16 offset = v_sub_wrap(vx_load(r.laneD + d), lowest);
        rivals = rivals | ((vx_load_aligned(key + d) < bound) & ~(v_min(offset, two) == offset));
    }
    const bool unique = !v_check_any(rivals);
#endif
    const bool inner = b > 0 && b < r.w.numDisp - 1;
    r.disparity16[x] = unique ? refinedDisparity16(inner ? key[b - 1] >> kWinnerKeyShift : 0, m,
                                                   inner ? key[b + 1] >> kWinnerKeyShift : 0, b, r.w)
                              : 0;
}

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
    alignas(64) uint16_t laneKey[kMaxPaddedDisp];
    for (int d = 0; d < paddedDisp; ++d) laneKey[d] = d < wp.numDisp ? static_cast<uint16_t>(d % kKeyGroup) : 0xFFFF;
    const UpRow r{paths.prevL[0], paths.prevMin[0], pp.p2ByStep, grey, greyPrev, cost, keptPath, forward, backward,
                  paths.curL[0], paths.curMin[0], best, bestSum, disparity16, paddedDisp, wp, laneKey,
                  keysBelow(wp.uniquenessPercent),
#if CV_SIMD_WIDTH == 64
                  allowedLanes()};
#else
                  laneDisparities()};
#endif
    const v_uint8 p1 = vx_setall_u8(static_cast<uint8_t>(pp.p1));
    // The keys of a batch of pixels first, then their winners: a winner is a chain of
    // dependent steps (least key, uniqueness, parabola), and the chains of neighbouring
    // pixels, side by side in the instruction stream, overlap.
    constexpr int kBatch = 8;
    alignas(64) uint16_t keys[kBatch][kMaxPaddedDisp];
    int winner[kBatch], leastSum[kBatch];
    for (int x0 = 0; x0 < width; x0 += kBatch) {
        const int n = std::min(kBatch, width - x0);
        for (int j = 0; j < n; ++j) leastSum[j] = upKeysOf<Chunks>(r, p1, x0 + j, keys[j], winner[j]);
        for (int j = 0; j < n; ++j) upWinnerOf<Chunks>(r, x0 + j, keys[j], winner[j], leastSum[j]);
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
