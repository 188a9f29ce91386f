// SPDX-License-Identifier: MIT
// sgm: the SIMD kernels compiled for AVX2 (32-byte vectors), used only when the CPU has
// it. This file alone is built with -mavx2; OpenCV's intrinsics go into a namespace of
// their own (hal_sgm_avx2), so the linker never mixes this code with the baseline's.
#include "sgm_kernels.hpp"

#if defined(SGM_BUILD_AVX2)
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE hal_sgm_avx2
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE_BEGIN namespace hal_sgm_avx2 {
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE_END }
#include "sgm_simd_avx2_level.h"
#define SGM_SIMD_NS avx2
#include "sgm_kernels_simd.inl"

namespace sgm {
// Called only after the baseline code checked the CPU (avx2Kernels).
const Kernels *avx2Table() { return &avx2::table("avx2"); }
} // namespace sgm
#endif
