// SPDX-License-Identifier: MIT
// sgm: the CPU level OpenCV's universal intrinsics are told to use in the 256-bit kernel
// files (sgm_kernels_avx2.cpp, sgm_kernels_avx512.cpp). OpenCV picks its intrinsics from
// these macros (its own build sets them; a user of the installed headers gets SSE2 only
// unless it says more). Each including file first names its own HAL namespace
// (CV_CPU_OPTIMIZATION_HAL_NAMESPACE*), so the linker never mixes the files' code.
#pragma once
#define CV_SSE3 1
#define CV_SSSE3 1
#define CV_SSE4_1 1
#define CV_SSE4_2 1
#define CV_POPCNT 1
#define CV_AVX 1
#define CV_FP16 1
#define CV_FMA3 1
#define CV_AVX2 1
