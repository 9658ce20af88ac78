#pragma once
// The local shape at a point, each formula once for every estimator: the tangent frame of a unit
// normal (Duff et al. 2017), a neighbour's normal ray in it (paper eq. 3), the principal axes of
// a symmetric 2x2 shape operator and the point's class from its principal curvatures.
//
// Templates on the element type (kernels/vec3.h): float in the CUDA kernels and the image-space
// estimator, double in the CPU paths (through the Eigen adapters of curvature/vertex_rows.h and
// curvature/normal_rays_detail.h, and in normals/jets.cpp), GCC vector types in the CPU lane
// kernels (curvature.cpp: the closed-form per-vertex fit; triangle_curvature.cpp: the per-face
// solve). Plain data, no Eigen: nvcc compiles this header.
//
// Rounding. Where a formula divides two numerators by one denominator the estimators made
// different choices before this header held the formula once, and each keeps its own so that its
// results stay bit for bit (Quotient): the lane kernels, the CUDA per-vertex fit and the
// characteristic equation of kernels/triplet.h (the per-triangle solve on the CPU and the device,
// image space) multiply by one reciprocal (the divider is the lane kernels' narrowest port), the
// Eigen path divides the ray's slopes and the principal direction, the image-space window divides
// both of its principal axes' quotients. The choices move a result by an ulp at most.

#include "focal/core/point_class.h"
#include "kernels/host_device.h"
#include "kernels/vec3.h"

namespace focal::kernels {

/// How a formula divides numerators by a common denominator: `exact` divides each (correctly
/// rounded); `reciprocal` multiplies each by one rounded reciprocal (one division instead of
/// two; each quotient may differ from the exact one by an ulp).
enum class Quotient { exact, reciprocal };

/// a / d and b / d, as `q` says.
template <Quotient q, class T>
FOCAL_HD_INLINE void divide(T& a, T& b, T d) {
  if constexpr (q == Quotient::exact) {
    a = a / d, b = b / d;
  } else {
    const T inverse = Element<T>(1) / d;
    a = a * inverse, b = b * inverse;
  }
}

// ---------------------------------------------------------------------------------------------
// Tangent frame.

/// A right-handed orthonormal frame (x, y, n) of the tangent plane of unit normal n.
template <class T>
struct alignas(sizeof(T)) Frame {
  Vec3<T> x, y, n;
  /// The 3D direction of tangent-plane coordinates (a, b): a x + b y.
  FOCAL_HD_INLINE Vec3<T> from_plane(T a, T b) const { return a * x + b * y; }
};

/// The frame of the unit normal n: Duff et al., "Building an Orthonormal Basis, Revisited"
/// (JCGT 2017). Continuous everywhere except across n.z = 0's sign flip, branch-free and
/// orthonormal up to rounding; the frame in which every estimator expresses 2D quantities (shape
/// operators, principal directions), so that they agree across estimators.
template <class T>
FOCAL_HD_INLINE Frame<T> frame_of(Vec3<T> n) {
  using S = Element<T>;
  const T sign = copysign_of(splat<T>(1), n.z);
  const T a = S(-1) / (sign + n.z);
  const T b = n.x * n.y * a;
  return {{S(1) + sign * n.x * n.x * a, sign * b, -sign * n.x}, {b, sign + n.y * n.y * a, -n.y}, n};
}

// ---------------------------------------------------------------------------------------------
// Normal rays.

/// A ray of the two-slit model in a frame (x, y, n) (paper eq. 3): it passes through (u, v, 0)
/// with direction (sigma, tau, 1).
template <class T>
struct alignas(sizeof(T)) NormalRay {
  T sigma, tau, u, v;
};

/// The normal ray in frame f of a neighbour at `offset` (its position minus the frame's origin)
/// with unit normal m: sigma = x.m / n.m, tau = y.m / n.m, u = x.o - (n.o) sigma, v = y.o -
/// (n.o) tau. `slope` is m or any vector with m's tangential components (x.slope = x.m,
/// y.slope = y.m): the CUDA fit passes m minus the vertex normal, which float resolves better.
/// Writes `ray` (any type with members sigma, tau, u, v) always; returns where it exists: m in
/// the open hemisphere of f.n (n.m > 0, false for NaN) and sigma, tau, u, v finite.
template <Quotient q, class T, class Ray>
FOCAL_HD_INLINE Mask<T> normal_ray(const Frame<T>& f, Vec3<T> offset, Vec3<T> m, Vec3<T> slope,
                                   Ray& ray) {
  const T m_n = dot(f.n, m);
  T sigma = dot(f.x, slope), tau = dot(f.y, slope);
  divide<q>(sigma, tau, m_n);
  const T o_n = dot(f.n, offset);
  const T u = dot(f.x, offset) - o_n * sigma;
  const T v = dot(f.y, offset) - o_n * tau;
  ray.sigma = sigma, ray.tau = tau, ray.u = u, ray.v = v;
  return (m_n > Element<T>(0)) & is_finite(sigma + tau + u + v);
}

// ---------------------------------------------------------------------------------------------
// Principal axes.

/// The eigen-decomposition of a symmetric [a b; b c]: k1 >= k2 and the unit d1 = (d1x, d1y) of
/// k1 with angle in (-pi/2, pi/2]; d2 is d1 turned by +90 degrees, (-d1y, d1x), so that (d1, d2,
/// n) is right-handed in a frame (x, y, n). Where the operator is isotropic (a = c, b = 0) every
/// direction is principal: d1 = (1, 0) then, and `isotropic` is set.
template <class T>
struct alignas(sizeof(T)) Principal {
  T k1, k2, d1x, d1y;
  Mask<T> isotropic;
};

/// principal_axes' two divisions: the operator scaled to s = max(|d|, |b|), the direction
/// normalised (see Quotient).
template <Quotient scale, Quotient normalise, class T>
FOCAL_HD_INLINE Principal<T> principal_axes(T a, T b, T c) {
  using S = Element<T>;
  const T mean = S(0.5) * (a + c);
  const T d = S(0.5) * (a - c);
  // In units of s = max(|d|, |b|) squares neither overflow nor underflow, as with hypot; with
  // the algebraic eigenvector below this avoids hypot, atan2 and sincos. s = 0: isotropic, its
  // lanes divided by 1 instead and replaced below.
  const T s = max_of(abs_of(d), abs_of(b));
  const Mask<T> isotropic = s == S(0);
  const T one = splat<T>(1);
  T ds = d, bs = b;
  divide<scale>(ds, bs, isotropic ? one : s);
  const T r = sqrt_of(ds * ds + bs * bs);  // half the eigenvalue gap, over s
  // The eigenvector of k1 with angle in (-pi/2, pi/2]: (r + d, b), or where that cancels
  // (d < 0) the parallel (b, r - d) turned to x >= 0. Both have length sqrt(2 r (r + |d|)).
  const Mask<T> positive = ds >= S(0);
  T x = positive ? r + ds : abs_of(bs);
  T y = positive ? bs : copysign_of(r - ds, bs);
  divide<normalise>(x, y, sqrt_of(S(2) * r * (r + abs_of(ds))));
  return {isotropic ? mean : mean + s * r, isotropic ? mean : mean - s * r, isotropic ? one : x,
          isotropic ? splat<T>(0) : y, isotropic};
}

// ---------------------------------------------------------------------------------------------
// Classification.

template <class T>
FOCAL_HD_INLINE ClassCode<T> class_code(PointClass c) {
  return static_cast<ClassCode<T>>(ClassCode<T>{} + static_cast<std::int64_t>(c));
}

/// The class of a point with principal curvatures k1 >= k2 (focal::classify): |k| <=
/// zero_tolerance counts as zero; k1 - k2 <= umbilic_tolerance max(|k1|, |k2|) as umbilic; a
/// curvature that is not finite gives `undefined`. PointClass codes.
template <class T>
FOCAL_HD_INLINE ClassCode<T> classify(T k1, T k2, Element<T> zero_tolerance,
                                      Element<T> umbilic_tolerance) {
  const T a1 = abs_of(k1), a2 = abs_of(k2);
  const Mask<T> zero1 = a1 <= zero_tolerance, zero2 = a2 <= zero_tolerance;
  // The tests in reverse order of precedence, each overriding the ones before where it holds.
  ClassCode<T> c = k1 * k2 > Element<T>(0) ? class_code<T>(PointClass::elliptic)
                                           : class_code<T>(PointClass::hyperbolic);
  c = k1 - k2 <= umbilic_tolerance * max_of(a1, a2) ? class_code<T>(PointClass::umbilic) : c;
  c = (zero1 | zero2) ? class_code<T>(PointClass::parabolic) : c;
  c = (zero1 & zero2) ? class_code<T>(PointClass::flat) : c;
  return (is_finite(k1) & is_finite(k2)) ? c : class_code<T>(PointClass::undefined);
}

}  // namespace focal::kernels
