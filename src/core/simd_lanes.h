#pragma once
// Vectors of doubles for the kernels that run one vertex or one face per lane (the closed-form
// fit, the per-triangle solve), in GCC vector types of the native width of each instruction set:
// 8 lanes with AVX-512, 4 with AVX2, 2 with baseline x86-64 (SSE2). Wider types than the target
// has are not used: GCC then turns comparisons and selects into scalar code.
//
// The formulas the kernels share with the scalar and CUDA paths (frame, normal ray, principal
// axes, classes) are kernels/local_shape.h's, on these types through kernels/vec3.h; the helpers
// here are the lane primitives they and the kernels' own code use.
//
// Each kernel is a template on its lane type, compiled once per instruction set (functions with a
// `target` attribute around one always-inline body) and picked at run time by simd_isa(). Only
// lane-wise IEEE operations are used (+ - * / sqrt, comparisons, selects; no FMA: the kernel
// files are built with -ffp-contract=off, since GCC's avx512f target implies FMA) and no lane
// ever reads another, so every instruction set and every thread count gives the same bits.

#include <cstdint>

// The helpers below take vectors by value; they are always inlined, so GCC's note on the ABI of
// such signatures outside AVX code does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace focal::detail {

using Lanes2 = double __attribute__((vector_size(16)));
// Aligned explicitly: outside AVX code GCC gives wider vectors a smaller alignment, and storage
// allocated there (std::vector) is then accessed with aligned AVX moves.
using Lanes4 = double __attribute__((vector_size(32), aligned(32)));
using Lanes8 = double __attribute__((vector_size(64), aligned(64)));

template <class L>
constexpr int lane_count = static_cast<int>(sizeof(L) / sizeof(double));
/// -1 / 0 per lane, as comparisons of L give.
template <class L>
using MaskOf = decltype(L{} < L{});

/// The instruction sets a lane kernel is compiled for; `best` is the fastest the CPU runs.
enum class SimdIsa { best, avx512, avx2, baseline };

/// True where this CPU (and this build) can run kernels compiled for `isa`.
inline bool simd_isa_available(SimdIsa isa) {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
  switch (isa) {
    case SimdIsa::avx512:  // x86-64-v4: DQ for int64 <-> double, VL and BW for the masks
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw");
    case SimdIsa::avx2:
      return __builtin_cpu_supports("avx2");
    default:
      return true;
  }
#else
  return isa == SimdIsa::best || isa == SimdIsa::baseline;
#endif
}

/// `requested`, with `best` resolved: AVX2 before AVX-512. GCC 12 spills the 8-lane build's
/// many live vectors and turns some of its mask operations into scalar code, so the 4-lane AVX2
/// build is the one run. The AVX-512 build stays compiled and tested (same bits), for other
/// compilers.
inline SimdIsa simd_isa(SimdIsa requested = SimdIsa::best) {
  if (requested != SimdIsa::best) return requested;
  if (simd_isa_available(SimdIsa::avx2)) return SimdIsa::avx2;
  if (simd_isa_available(SimdIsa::avx512)) return SimdIsa::avx512;
  return SimdIsa::baseline;
}

/// The build of a kernel for `requested` (see simd_isa) among its three builds.
template <class Kernel>
Kernel kernel_for(SimdIsa requested, Kernel avx512, Kernel avx2, Kernel baseline) {
  switch (simd_isa(requested)) {
    case SimdIsa::avx512:
      return avx512;
    case SimdIsa::avx2:
      return avx2;
    default:
      return baseline;
  }
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FOCAL_TARGET_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl,avx512bw")))
#define FOCAL_TARGET_AVX2 __attribute__((target("avx2")))
#else
#define FOCAL_TARGET_AVX512
#define FOCAL_TARGET_AVX2
#endif

#define FOCAL_LANE_INLINE [[gnu::always_inline]] inline
// Lambdas that take or return vectors: a lambda does not inherit its enclosing function's
// `target`, so one left out of line (as in unoptimised or sanitizer builds) would be compiled for
// baseline x86-64 and pass 32- and 64-byte vectors with another ABI than its AVX caller expects.
#define FOCAL_LANE_LAMBDA __attribute__((always_inline))

template <class L>
FOCAL_LANE_INLINE L broadcast(double x) {
  return L{} + x;
}

/// The vector {f(0), f(1), ...} (of doubles or of int64), built in registers: lanes written to
/// memory and loaded as one vector stall on store forwarding.
template <class V, class Lane>
FOCAL_LANE_INLINE V lanes_of(Lane f) {
  if constexpr (sizeof(V) == 64) {
    return V{f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7)};
  } else if constexpr (sizeof(V) == 32) {
    return V{f(0), f(1), f(2), f(3)};
  } else {
    return V{f(0), f(1)};
  }
}

template <class L>
FOCAL_LANE_INLINE L lane_abs(L x) {
  return reinterpret_cast<L>(reinterpret_cast<MaskOf<L>>(x) & INT64_MAX);
}

/// std::copysign(magnitude, sign) per lane.
template <class L>
FOCAL_LANE_INLINE L lane_copysign(L magnitude, L sign) {
  return reinterpret_cast<L>((reinterpret_cast<MaskOf<L>>(magnitude) & INT64_MAX) |
                             (reinterpret_cast<MaskOf<L>>(sign) & INT64_MIN));
}

/// std::sqrt per lane: the loop becomes one vector square root (-fno-math-errno, see
/// src/CMakeLists.txt), correctly rounded like the scalar one.
template <class L>
FOCAL_LANE_INLINE L lane_sqrt(L x) {
  L r;
  for (int l = 0; l < lane_count<L>; ++l) r[l] = __builtin_sqrt(x[l]);
  return r;
}

/// Unaligned whole-vector load and store.
template <class L>
FOCAL_LANE_INLINE L load_lanes(const double* p) {
  L x;
  __builtin_memcpy(&x, p, sizeof x);
  return x;
}
template <class L>
FOCAL_LANE_INLINE void store_lanes(double* p, L x) {
  __builtin_memcpy(p, &x, sizeof x);
}

}  // namespace focal::detail

#pragma GCC diagnostic pop
