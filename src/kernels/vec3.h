#pragma once
// The arithmetic of the kernels: scalar helpers and one Vec3, for every element type a kernel is
// instantiated on: float (the CUDA kernels, the image-space estimator), double (the CPU paths and
// the tests' checks of the float formulas) and, on the CPU, the GCC vector types of
// core/simd_lanes.h (one vertex or face per lane). Formulas written once on these helpers
// (kernels/local_shape.h) compile for all of them.
//
// A formula on these types never branches on a value: it computes both sides and selects with
// `c ? a : b`, which GCC evaluates lane by lane on vectors (c a mask) and which is the plain
// conditional on scalars (c a bool). The helpers below are exact (IEEE sqrt, sign-bit abs and
// copysign), so a scalar and a lane running the same formula give the same bits.

#include <math.h>  // sqrtf, sqrt, fabsf, ... : the C names are the ones CUDA provides on the device

#include <cstdint>

#include "kernels/host_device.h"

#ifndef __CUDACC__
#include <concepts>
#include <type_traits>

#include "core/simd_lanes.h"
#endif

namespace focal::kernels {

// ---------------------------------------------------------------------------------------------
// Element types.

/// The scalar type of T's elements (T for float and double; double for a lane vector).
template <class T>
struct ElementOf {
  using type = T;
};
template <class T>
using Element = typename ElementOf<T>::type;

/// What comparisons of T give: bool for scalars, a vector of 0 / -1 for lanes.
template <class T>
using Mask = decltype(T{} < T{});

/// A point class's code as a formula on T returns it: the byte of PointClass for scalars, a
/// vector of int64 codes (as Mask<T>) for lanes.
template <class T>
struct ClassCodeOf {
  using type = std::uint8_t;
};
template <class T>
using ClassCode = typename ClassCodeOf<T>::type;

/// x in every element of T.
template <class T>
FOCAL_HD_INLINE T splat(Element<T> x) {
  return T{} + x;
}

FOCAL_HD_INLINE float sqrt_of(float v) { return sqrtf(v); }
FOCAL_HD_INLINE double sqrt_of(double v) { return sqrt(v); }
FOCAL_HD_INLINE float abs_of(float v) { return fabsf(v); }
FOCAL_HD_INLINE double abs_of(double v) { return fabs(v); }
FOCAL_HD_INLINE float copysign_of(float m, float s) { return copysignf(m, s); }
FOCAL_HD_INLINE double copysign_of(double m, double s) { return copysign(m, s); }

#ifndef __CUDACC__
/// The GCC vector types of core/simd_lanes.h (Lanes2, Lanes4, Lanes8).
template <class L>
concept LaneVector = !std::is_pointer_v<L> && requires(L x) {
  { x[0] } -> std::same_as<double&>;
};
template <LaneVector L>
struct ElementOf<L> {
  using type = double;
};
template <LaneVector L>
struct ClassCodeOf<L> {
  using type = detail::MaskOf<L>;
};
template <LaneVector L>
FOCAL_LANE_INLINE L sqrt_of(L v) {
  return detail::lane_sqrt(v);
}
template <LaneVector L>
FOCAL_LANE_INLINE L abs_of(L v) {
  return detail::lane_abs(v);
}
template <LaneVector L>
FOCAL_LANE_INLINE L copysign_of(L m, L s) {
  return detail::lane_copysign(m, s);
}
#endif

template <class T>
FOCAL_HD T quiet_nan();
template <>
FOCAL_HD inline float quiet_nan<float>() {
  return nanf("");
}
template <>
FOCAL_HD inline double quiet_nan<double>() {
  return nan("");
}

/// False for NaN and +-inf (v - v is NaN for both), without the device/host split of isfinite.
template <class T>
FOCAL_HD_INLINE Mask<T> is_finite(T v) {
  return v - v == Element<T>(0);
}

/// std::max(a, b): a where b is not larger, NaN in b included; b < a ? a : b is std::max(b, a).
template <class T>
FOCAL_HD_INLINE T max_of(T a, T b) {
  return a < b ? b : a;
}

// ---------------------------------------------------------------------------------------------
// Vectors. Aligned to their element's size: a lane type's own alignment is lost as a template
// argument, and the AVX-512 code moves these with aligned loads and stores.

template <class T>
struct alignas(sizeof(T)) Vec3 {
  T x, y, z;
};
template <class T>
FOCAL_HD_INLINE Vec3<T> operator+(Vec3<T> a, Vec3<T> b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
FOCAL_HD_INLINE Vec3<T> operator-(Vec3<T> a, Vec3<T> b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
FOCAL_HD_INLINE Vec3<T> operator*(T s, Vec3<T> a) {
  return {s * a.x, s * a.y, s * a.z};
}
/// (a.x b.x + a.y b.y) + a.z b.z, the order of Eigen's Vector3d::dot.
template <class T>
FOCAL_HD_INLINE T dot(Vec3<T> a, Vec3<T> b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
FOCAL_HD_INLINE Vec3<T> cross(Vec3<T> a, Vec3<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
FOCAL_HD_INLINE T norm(Vec3<T> a) {
  return sqrt_of(dot(a, a));
}
template <class T>
FOCAL_HD_INLINE Mask<T> is_finite(Vec3<T> a) {
  return is_finite(a.x) & is_finite(a.y) & is_finite(a.z);
}
/// The largest absolute component.
template <class T>
FOCAL_HD T max_abs(Vec3<T> a) {
  return max_of(max_of(abs_of(a.x), abs_of(a.y)), abs_of(a.z));
}
/// |a| without over- or underflow of the squares (as hypot does): float squares overflow from
/// 1.8e19 and underflow below 1.1e-19, well inside the range of coordinates. NaN when a
/// component is not finite.
template <class T>
FOCAL_HD T length(Vec3<T> a) {
  if (!is_finite(a)) return quiet_nan<T>();
  const T m = max_abs(a);
  return m > T(0) ? m * norm((T(1) / m) * a) : T(0);
}
template <class T, class U>
FOCAL_HD Vec3<T> vec_cast(Vec3<U> a) {
  return {T(a.x), T(a.y), T(a.z)};
}
template <class T>
FOCAL_HD Vec3<T> load3(const T* p) {
  return {p[0], p[1], p[2]};
}
template <class T>
FOCAL_HD void store3(T* p, Vec3<T> a) {
  p[0] = a.x, p[1] = a.y, p[2] = a.z;
}
template <class T>
FOCAL_HD Vec3<T> nan3() {
  return {quiet_nan<T>(), quiet_nan<T>(), quiet_nan<T>()};
}

}  // namespace focal::kernels
