// SPDX-License-Identifier: MIT
// sgm: the SIMD horizontal paths, left to right and right to left, of one or
// two rows side by side, as sums or kept whole. A part of
// sgm_kernels_simd.inl, included by it inside its namespaces: not a header of its own.
#ifndef SGM_SIMD_NS
#error "sgm_kernels_simd_horizontal.inl is included by sgm_kernels_simd.inl only"
#endif

// ---- horizontal paths -----------------------------------------------------------------

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
