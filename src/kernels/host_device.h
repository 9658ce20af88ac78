#pragma once
// FOCAL_HD marks plain-data math that nvcc compiles for the GPU and g++ for the CPU, so that the
// CUDA kernels and the CPU code (and its tests) share one formula.
//
// FOCAL_HD_INLINE marks the small formulas that the CPU's lane kernels also instantiate on GCC
// vector types (kernels/vec3.h): those are called from functions compiled for AVX2 or AVX-512
// (core/simd_lanes.h), and an out-of-line copy (as in unoptimised or sanitizer builds) would be
// compiled for baseline x86-64 and take 32- and 64-byte vectors with another ABI than its caller
// passes. Always inlined, they take their caller's instruction set.

#ifdef __CUDACC__
#define FOCAL_HD __host__ __device__
#define FOCAL_HD_INLINE __host__ __device__ __forceinline__
#else
#define FOCAL_HD
#define FOCAL_HD_INLINE [[gnu::always_inline]] inline
#endif
