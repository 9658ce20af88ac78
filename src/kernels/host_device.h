#pragma once
// FOCAL_HD marks plain-data math that nvcc compiles for the GPU and g++ for the CPU, so that the
// CUDA kernels and the CPU code (and its tests) share one formula.

#ifdef __CUDACC__
#define FOCAL_HD __host__ __device__
#else
#define FOCAL_HD
#endif
