// SPDX-License-Identifier: MIT
// sgm: the SIMD kernels for the compiler's baseline instruction set (SSE2 on x86-64,
// NEON on aarch64), and the choice of the fastest table this CPU runs.
#define SGM_SIMD_NS baseline
#include "sgm_kernels_simd.inl"

namespace sgm {

const Kernels *baselineKernels() {
#if CV_SIMD
    return &baseline::table("baseline");
#else
    return nullptr;
#endif
}

#if defined(SGM_BUILD_AVX2)
const Kernels *avx2Table(); // sgm_kernels_avx2.cpp
#endif
#if defined(SGM_BUILD_AVX512)
const Kernels *avx512Table(); // sgm_kernels_avx512.cpp
#endif

// The CPU check lives here, in code built for the baseline: the AVX2 file may use AVX2
// anywhere, so nothing of it runs before this says yes.
const Kernels *avx2Kernels() {
#if defined(SGM_BUILD_AVX2)
    static const bool supported = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt") &&
                                  __builtin_cpu_supports("fma");
    return supported ? avx2Table() : nullptr;
#else
    return nullptr;
#endif
}

const Kernels *avx512Kernels() {
#if defined(SGM_BUILD_AVX512)
    static const bool supported =
        avx2Kernels() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq") &&
        __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512vbmi") &&
        __builtin_cpu_supports("avx512vpopcntdq") && __builtin_cpu_supports("avx512bitalg");
    return supported ? avx512Table() : nullptr;
#else
    return nullptr;
#endif
}

const Kernels &bestKernels() {
    if (const Kernels *k = avx512Kernels()) return *k;
    if (const Kernels *k = avx2Kernels()) return *k;
    if (const Kernels *k = baselineKernels()) return *k;
    return scalarKernels();
}

} // namespace sgm
