// SPDX-License-Identifier: MIT
// sgm: the AVX2 kernels again, with the census costs counted by AVX-512 VPOPCNTDQ (on
// 256-bit vectors, AVX-512 VL): used only when the CPU has both. This file alone is
// built with those flags; its intrinsics go into a namespace of their own (hal_sgm_avx512).
#include "sgm_kernels.hpp"

#if defined(SGM_BUILD_AVX512)
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE hal_sgm_avx512
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE_BEGIN namespace hal_sgm_avx512 {
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE_END }
#include "sgm_simd_avx2_level.h"
#define SGM_SIMD_VPOPCNT 1
#define SGM_SIMD_NS avx512
#include "sgm_kernels_simd.inl"

namespace sgm {
// Called only after the baseline code checked the CPU (avx512Kernels).
const Kernels *avx512Table() { return &avx512::table("avx512"); }
} // namespace sgm
#endif
