// SPDX-License-Identifier: MIT
// sgm: the SIMD paths whose predecessors lie in the previous row (vertical and
// diagonal), with or without sums, and a kept path added to sums. A part of
// sgm_kernels_simd.inl, included by it inside its namespaces: not a header of its own.
#ifndef SGM_SIMD_NS
#error "sgm_kernels_simd_paths.inl is included by sgm_kernels_simd.inl only"
#endif

// ---- paths ----------------------------------------------------------------------------

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
