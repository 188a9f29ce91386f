// SPDX-License-Identifier: MIT
// sgm: the AVX2 kernels again, with the census costs counted by AVX-512 VPOPCNTDQ (on
// 256-bit vectors, AVX-512 VL): used only when the CPU has both. This file alone is
// built with those flags; its intrinsics go into a namespace of their own (hal_sgm_avx512).
#include "sgm_kernels.hpp"

#if defined(SGM_BUILD_AVX512)
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE hal_sgm_avx512
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE_BEGIN namespace hal_sgm_avx512 {
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE_END }
#define CV_SSE3 1
#define CV_SSSE3 1
#define CV_SSE4_1 1
#define CV_SSE4_2 1
#define CV_POPCNT 1
#define CV_AVX 1
#define CV_FP16 1
#define CV_FMA3 1
#define CV_AVX2 1
#define SGM_SIMD_VPOPCNT 1
#define SGM_SIMD_NS avx512
#include "sgm_kernels_simd.inl"

namespace sgm {
// Called only after the baseline code checked the CPU (avx512Kernels).
const Kernels *avx512Table() { return &avx512::table("avx512"); }
} // namespace sgm
#endif
