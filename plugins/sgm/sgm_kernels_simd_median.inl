// SPDX-License-Identifier: MIT
// sgm: the SIMD median filter on the disparity, and its conversion to pixels. A part of
// sgm_kernels_simd.inl, included by it inside its namespaces: not a header of its own.
#ifndef SGM_SIMD_NS
#error "sgm_kernels_simd_median.inl is included by sgm_kernels_simd.inl only"
#endif

// ---- median ---------------------------------------------------------------------------
// kLanes16 windows side by side, a lane each: the networks of sgm_median.hpp on vectors.
inline __attribute__((always_inline)) void exchange(v_uint16 &a, v_uint16 &b) {
    const v_uint16 least = v_min(a, b);
    b = v_max(a, b);
    a = least;
}

template <int K>
inline __attribute__((always_inline)) void sortColumn(v_uint16 *v) {
    if constexpr (K == 3) {
        for (const auto &c : kSort3) exchange(v[c[0]], v[c[1]]);
    } else {
        for (const auto &c : kSort5) exchange(v[c[0]], v[c[1]]);
    }
}

// The network unrolled at compile time (its wires become registers).
template <const auto &Net, size_t... C>
inline __attribute__((always_inline)) void selectMedian(v_uint16 *v, std::index_sequence<C...>) {
    const auto step = [v](const MedianComparator &c) __attribute__((always_inline)) {
        const v_uint16 a = v[c.i], b = v[c.j];
        if (c.keep & 1) v[c.i] = v_min(a, b);
        if (c.keep & 2) v[c.j] = v_max(a, b);
    };
    (step(Net[C]), ...);
}

// Disparities in 1/16 px to pixels, `invalid` where 0 (as the scalar reference: the
// product by 1/16 is exact).
inline void storePixels(const v_uint16 &d16, float invalid, float *out) {
    constexpr int kLanes32 = v_float32::nlanes;
    v_uint32 lo, hi;
    v_expand(d16, lo, hi);
    const v_float32 scale = vx_setall_f32(1.0f / 16), none = vx_setall_f32(invalid), zero = vx_setzero_f32();
    const v_float32 a = v_cvt_f32(v_reinterpret_as_s32(lo)) * scale, b = v_cvt_f32(v_reinterpret_as_s32(hi)) * scale;
    v_store(out, v_select(a == zero, none, a));
    v_store(out + kLanes32, v_select(b == zero, none, b));
}

// Vectors of kLanes16 pixels from x = 0; the last one ends at the row's end (it overlaps
// the one before, whose lanes it computes again to the same values): width >= kLanes16.
template <class Step>
inline void acrossRow(int width, const Step &step) {
    for (int x0 = 0; x0 < width; x0 += kLanes16) step(std::min(x0, width - kLanes16));
}

template <int K, const auto &Net>
void medianOf(const uint16_t *const *rows, int width, uint16_t *scratch, float invalid, float *out) {
    constexpr int R = K / 2;
    const size_t stride = static_cast<size_t>(width) + kMaxMedianPx + 64;
    // The row's columns, each sorted (sorted[r][x]: the r-th least of column x), with R
    // columns repeated on either side.
    uint16_t *sorted[K];
    for (int r = 0; r < K; ++r) sorted[r] = scratch + r * stride + R;
    acrossRow(width, [&](int x) {
        v_uint16 v[K];
        for (int r = 0; r < K; ++r) v[r] = vx_load(rows[r] + x);
        sortColumn<K>(v);
        for (int r = 0; r < K; ++r) v_store(sorted[r] + x, v[r]);
    });
    for (int r = 0; r < K; ++r)
        for (int i = 1; i <= R; ++i) {
            sorted[r][-i] = sorted[r][0];
            sorted[r][width - 1 + i] = sorted[r][width - 1];
        }
    acrossRow(width, [&](int x) {
        v_uint16 v[K * K];
        for (int r = 0; r < K; ++r)
            for (int c = 0; c < K; ++c) v[r * K + c] = vx_load(sorted[r] + x + c - R);
        selectMedian<Net>(v, std::make_index_sequence<std::size(Net)>());
        storePixels(v[K * K / 2], invalid, out + x);
    });
}

void medianRow(const uint16_t *const *rows, int width, int size, uint16_t *scratch, float invalid, float *out) {
    if (width < kLanes16) return scalarKernels().medianRow(rows, width, size, scratch, invalid, out);
    if (size == 5) return medianOf<5, kMedianOf25>(rows, width, scratch, invalid, out);
    if (size == 3) return medianOf<3, kMedianOf9>(rows, width, scratch, invalid, out);
    acrossRow(width, [&](int x) { storePixels(vx_load(rows[0] + x), invalid, out + x); });
}
