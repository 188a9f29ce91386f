// SPDX-License-Identifier: MIT
// sgm: the SIMD census transform of a row (full and centre-symmetric). A part of
// sgm_kernels_simd.inl, included by it inside its namespaces: not a header of its own.
#ifndef SGM_SIMD_NS
#error "sgm_kernels_simd_census.inl is included by sgm_kernels_simd.inl only"
#endif

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
