// SPDX-License-Identifier: MIT
// sgm: the SIMD kernels compiled for AVX-512 (64-byte vectors: a pixel's 64 disparities
// in one register, the census costs counted by VPOPCNTQ), used only when the CPU has every
// extension it is built with (avx512Kernels). This file alone is built with those flags;
// its intrinsics go into a namespace of their own (hal_sgm_avx512).
#include "sgm_kernels.hpp"

#if defined(SGM_BUILD_AVX512)
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE hal_sgm_avx512
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE_BEGIN namespace hal_sgm_avx512 {
#define CV_CPU_OPTIMIZATION_HAL_NAMESPACE_END }
#include "sgm_simd_avx2_level.h"
// OpenCV's 512-bit intrinsics (intrin_avx512.hpp), with the Ice Lake extensions it uses
// when told: VBMI (one byte permute for v_extract), VPOPCNTDQ and BITALG (popcounts).
#define CV_AVX_512F 1
#define CV_AVX512_COMMON 1
#define CV_AVX_512CD 1
#define CV_AVX512_SKX 1
#define CV_AVX_512VL 1
#define CV_AVX_512BW 1
#define CV_AVX_512DQ 1
#define CV_AVX_512VBMI 1
#define CV_AVX_512VPOPCNTDQ 1
#define CV_AVX_512BITALG 1
#define SGM_SIMD_NS avx512
#include "sgm_kernels_simd.inl"

namespace sgm {
// Called only after the baseline code checked the CPU (avx512Kernels).
const Kernels *avx512Table() { return &avx512::table("avx512"); }
} // namespace sgm
#endif
