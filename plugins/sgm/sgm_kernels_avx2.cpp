// SPDX-License-Identifier: MIT
// sgm: the SIMD kernels compiled for AVX2 (32-byte vectors), used only when the CPU has
// it. This file alone is built with -mavx2; OpenCV's intrinsics go into a namespace of
// their own (hal_sgm_avx2), so the linker never mixes this code with the baseline's.
#include "sgm_kernels.hpp"

#if defined(SGM_BUILD_AVX2)
// OpenCV picks its 256-bit intrinsics from these (its own build sets them; a user of the
// installed headers gets SSE2 only unless it says more).
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE hal_sgm_avx2
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE_BEGIN namespace hal_sgm_avx2 {
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
#define SGM_SIMD_NS avx2
#include "sgm_kernels_simd.inl"

namespace sgm {
// Called only after the baseline code checked the CPU (avx2Kernels).
const Kernels *avx2Table() { return &avx2::table("avx2"); }
} // namespace sgm
#endif
