#pragma once
// The characteristic equation of three normal rays (paper sections 4.2-4.3, eqs. 5-9) in plain
// data, written once for every element type (kernels/vec3.h): the per-face solve of
// triangle_curvature on the CPU (one face per lane of a GCC vector, in double), the CUDA
// per-triangle kernel and its CPU twin (float, kernels/triangle.h), the image-space estimator on
// the CPU and the device (float, kernels/pixel.h).
//
// The steps: the frame of the unit mean normal, the rays from the centroid, the sagitta
// correction, A, B, C of eq. 7, K = A / C, 2H = B / C, k = H +- sqrt(discriminant), directions
// from the symmetrised M = G X^-1 and slits from eq. 18. The operations and their order are those
// of the CPU's double path, the reference whose bits the outputs are (quotients by one
// reciprocal, kernels::Quotient::reciprocal). Two choices depend on the precision (Precision):
//  - float takes the positions relative to the triplet's centroid divided by the triplet's size
//    s before any product is formed, so that no intermediate over- or underflows whatever the
//    units and the results carry float's relative precision, not that of the coordinates;
//    double takes them relative to the centroid only (s = 1, an exact identity);
//  - float's discriminant is ((m00 - m11) / 2)^2 + m01 m10, which equals H^2 - K but does not
//    cancel two nearly equal squares at umbilics; double's is H^2 - K.
// Degeneracy tests are ratios (scale-free); their thresholds are per precision (Precision).

#include <math.h>  // INFINITY

#include "kernels/host_device.h"
#include "kernels/local_shape.h"
#include "kernels/vec3.h"

namespace focal::triplet {

// The arithmetic (kernels/vec3.h) and the local shape (kernels/local_shape.h) of every kernel.
using kernels::abs_of;
using kernels::cross;
using kernels::dot;
using kernels::Element;
using kernels::Frame;
using kernels::frame_of;
using kernels::is_finite;
using kernels::length;
using kernels::load3;
using kernels::Mask;
using kernels::max_abs;
using kernels::max_of;
using kernels::nan3;
using kernels::norm;
using kernels::Principal;
using kernels::quiet_nan;
using kernels::Quotient;
using kernels::splat;
using kernels::sqrt_of;
using kernels::store3;
using kernels::Vec3;
using kernels::vec_cast;

/// What depends on the precision S (the element type: double for the CPU's lanes too).
/// `degenerate`: a triangle of rays whose area in the ray frame is below this fraction of its
/// squared size (|det X| vs |X|_F^2, about sin of its smallest angle) has no usable shape
/// operator; 1e-14 in double, 1e-5 (about 80 float epsilons, the rounding of det X itself being 2
/// epsilons) in float. `slit`: eq. 18's slit vector counts as zero (umbilic) below this fraction
/// of its terms' size; 1e-9 in double, 1e-5 in float, where vectors that short are rounding
/// noise. `scaled` and `gap_discriminant`: see the file's comment.
template <class S>
struct Precision;
template <>
struct Precision<float> {
  static constexpr bool scaled = true;
  static constexpr bool gap_discriminant = true;
  FOCAL_HD_INLINE static float degenerate() { return 1e-5f; }
  FOCAL_HD_INLINE static float slit() { return 1e-5f; }
};
template <>
struct Precision<double> {
  static constexpr bool scaled = false;
  static constexpr bool gap_discriminant = false;
  FOCAL_HD_INLINE static double degenerate() { return 1e-14; }
  FOCAL_HD_INLINE static double slit() { return 1e-9; }
};

// ---------------------------------------------------------------------------------------------
// 2x2 algebra. Aligned to the element's size, as kernels::Vec3 (the lane types lose their own
// alignment as template arguments).

/// [a b; c d]: columns are the edges 0->1 and 0->2 for the triplet's X and G.
template <class T>
struct alignas(sizeof(T)) Mat2 {
  T a, b, c, d;
};
template <class T>
FOCAL_HD_INLINE T det(const Mat2<T>& m) {
  return m.a * m.d - m.c * m.b;
}
template <class T>
FOCAL_HD_INLINE T squared_norm(const Mat2<T>& m) {
  return (m.a * m.a + m.c * m.c) + (m.b * m.b + m.d * m.d);
}
/// G X^-1: X's inverse from one reciprocal of its determinant (as Eigen's 2x2 inverse), then the
/// product.
template <class T>
FOCAL_HD_INLINE Mat2<T> times_inverse(const Mat2<T>& g, const Mat2<T>& x) {
  const T inv = Element<T>(1) / det(x);
  const T i00 = x.d * inv, i01 = -x.b * inv, i10 = -x.c * inv, i11 = x.a * inv;
  return {g.a * i00 + g.b * i10, g.a * i01 + g.b * i11, g.c * i00 + g.d * i10,
          g.c * i01 + g.d * i11};
}

/// The principal axes of the symmetric [a b; b c] (kernels::principal_axes) as the image-space
/// window rounds them: both divisions exact.
template <class T>
FOCAL_HD_INLINE Principal<T> principal_of(T a, T b, T c) {
  return kernels::principal_axes<Quotient::exact, Quotient::exact>(a, b, c);
}

// ---------------------------------------------------------------------------------------------
// The characteristic equation, on any element type.

/// The equation of three rays: `valid` where it has a solution; elsewhere the other fields are
/// unspecified (a caller selects NaN there). X, G, M, the slit depths and `size` are in the
/// scaled units the equation was solved in (positions over `size`; size = 1 in double); the
/// coefficients and curvatures in world units.
template <class T>
struct alignas(sizeof(T)) Equation {
  Mask<T> valid;
  Frame<T> frame;  ///< frame.n is the unit mean of the three normals
  Mat2<T> X, G;    ///< rays in the frame, X after the sagitta correction
  Mat2<T> M;       ///< G X^-1, unsymmetrised, in scaled units
  T size;
  T A, B, C;  ///< eq. 7 in the frame (after the sagitta correction)
  T K, H, k1, k2;
  T lambda1, lambda2;          ///< focal depths -1 / k1, -1 / k2 (+-inf where k = 0)
  T slit_depth1, slit_depth2;  ///< the focal depths in scaled units (eq. 18's lambda)
  T relative_area;             ///< |C| in scaled units (see TripletSolution)
};

/// Solves the characteristic equation of the rays through positions p[i] along the unit normals
/// n[i], where `valid` (the caller's own conditions: unit normals that exist, active lanes).
/// Invalid besides where the three normals do not share a hemisphere with their mean, a ray
/// cannot be parametrised (kernels::normal_ray) or the rays' triangle has no area, before or
/// after the sagitta correction; in float also where a position is not finite or the points
/// coincide. The order of the points (the triplet's orientation) does not matter: swapping two
/// flips the signs of A, B, C together.
template <class T>
FOCAL_HD_INLINE Equation<T> characteristic_equation(const Vec3<T> p[3], const Vec3<T> n[3],
                                                    Mask<T> valid) {
  using S = Element<T>;
  using P = Precision<S>;
  Equation<T> e;
  // The frame of the mean normal (of (0, 0, 1) where there is none, so that invalid lanes stay
  // finite); the centroid as origin.
  const Vec3<T> sum = n[0] + n[1] + n[2];
  const T len = norm(sum);  // at most 3: no overflow
  valid &= (len > S(0)) & is_finite(len);
  const T zero = splat<T>(0), one = splat<T>(1);
  const T inv_len = S(1) / len;
  e.frame = frame_of(Vec3<T>{valid ? sum.x * inv_len : zero, valid ? sum.y * inv_len : zero,
                             valid ? sum.z * inv_len : one});
  const Frame<T>& f = e.frame;
  const S third = S(1) / S(3);
  const Vec3<T> centroid{(p[0].x + p[1].x + p[2].x) * third, (p[0].y + p[1].y + p[2].y) * third,
                         (p[0].z + p[1].z + p[2].z) * third};
  Vec3<T> q[3];
  for (int i = 0; i < 3; ++i) q[i] = p[i] - centroid;
  e.size = one;
  if constexpr (P::scaled) {
    // Divided by the triplet's size s (largest coordinate offset from the centroid, no squares
    // formed): X = O(1) and G = O(h k) whatever the units and the position.
    T size = zero;
    for (int i = 0; i < 3; ++i) {
      valid &= is_finite(q[i]);  // a NaN or infinite position
      size = max_of(size, max_abs(q[i]));
    }
    valid &= size > S(0);
    e.size = size;
    const T inv_size = S(1) / size;
    for (int i = 0; i < 3; ++i) q[i] = inv_size * q[i];
  }
  T u[3], v[3], sigma[3], tau[3], ox[3], oy[3];
  for (int i = 0; i < 3; ++i) {  // the point's ray and its tangential offset
    kernels::NormalRay<T> ray;
    valid &= kernels::normal_ray<Quotient::reciprocal>(f, q[i], n[i], n[i], ray);
    sigma[i] = ray.sigma, tau[i] = ray.tau, u[i] = ray.u, v[i] = ray.v;
    ox[i] = dot(f.x, q[i]);
    oy[i] = dot(f.y, q[i]);
  }
  Mat2<T> X{u[1] - u[0], u[2] - u[0], v[1] - v[0], v[2] - v[0]};
  const Mat2<T> G{sigma[1] - sigma[0], sigma[2] - sigma[0], tau[1] - tau[0], tau[2] - tau[0]};
  valid &= abs_of(det(X)) > P::degenerate() * squared_norm(X);  // area in the ray frame
  // The centroid lies below the surface by the sagitta s = (1/6) sum x^T M x (second order, x
  // the points' tangential offsets). Depths measured from the centroid's plane would carry that
  // O(h^2) bias into K and H, so the rays are re-parametrised on the plane z = s, the tangent
  // plane at the surface point above the centroid: (u, v) += s (sigma, tau).
  const Mat2<T> M0 = times_inverse(G, X);
  const T s01 = S(0.5) * (M0.b + M0.c);
  T sagitta = zero;
  for (int i = 0; i < 3; ++i) {
    sagitta += ox[i] * (M0.a * ox[i] + s01 * oy[i]) + oy[i] * (s01 * ox[i] + M0.d * oy[i]);
  }
  sagitta *= S(1) / S(6);
  X.a += sagitta * G.a, X.b += sagitta * G.b;
  X.c += sagitta * G.c, X.d += sagitta * G.d;
  const T A = det(G);
  const T B = G.a * X.d - G.b * X.c - G.c * X.b + G.d * X.a;
  const T C = det(X);
  valid &= abs_of(C) > P::degenerate() * squared_norm(X);
  const T inv_C = S(1) / C;
  const T K = A * inv_C, H = S(0.5) * (B * inv_C);
  e.M = times_inverse(G, X);  // on the corrected X
  // Below zero only through rounding or an unsymmetric M (noise): the double root H.
  T root;
  if constexpr (P::gap_discriminant) {
    const T half_gap = S(0.5) * (e.M.a - e.M.d);
    // max_of(0, x), not (x, 0): NaN (an M that overflowed) gives the double root too.
    root = sqrt_of(max_of(zero, half_gap * half_gap + e.M.b * e.M.c));
  } else {
    root = sqrt_of(max_of(H * H - K, zero));
  }
  const T size = e.size;
  e.valid = valid;
  e.X = X, e.G = G;
  e.A = A, e.B = B * size, e.C = C * size * size;
  e.K = K / size / size, e.H = H / size;
  e.k1 = (H + root) / size, e.k2 = (H - root) / size;
  e.lambda1 = S(-1) / e.k1, e.lambda2 = S(-1) / e.k2;
  e.slit_depth1 = S(-1) / (H + root), e.slit_depth2 = S(-1) / (H - root);
  e.relative_area = abs_of(C);
  return e;
}

/// The unit principal directions d1 (of k1) and d2 = d1 turned by +90 degrees, in the plane of
/// e.frame, from the symmetrised M.
template <class T>
FOCAL_HD_INLINE Principal<T> principal_directions(const Equation<T>& e) {
  return kernels::principal_axes<Quotient::reciprocal, Quotient::reciprocal>(
      e.M.a, Element<T>(0.5) * (e.M.b + e.M.c), e.M.d);
}

/// Unit slit direction (2D) at scaled focal depth lambda from eq. 18, along whichever edge gives
/// the longer vector; (0, 0) where both vanish (umbilic: all three rays meet in one point).
template <class T>
FOCAL_HD_INLINE void slit_direction(const Mat2<T>& X, const Mat2<T>& G, T lambda, T& sx, T& sy) {
  using S = Element<T>;
  const Mask<T> infinite = abs_of(lambda) == S(INFINITY);  // the direction's limit there
  const T ax = infinite ? G.a : X.a + lambda * G.a;
  const T ay = infinite ? G.c : X.c + lambda * G.c;
  const T bx = infinite ? G.b : X.b + lambda * G.b;
  const T by = infinite ? G.d : X.d + lambda * G.d;
  const T a2 = ax * ax + ay * ay, b2 = bx * bx + by * by;
  const Mask<T> a_longer = a2 >= b2;
  const T lx = a_longer ? ax : bx, ly = a_longer ? ay : by, l2 = a_longer ? a2 : b2;
  const T g = sqrt_of(squared_norm(G));
  const T scale = sqrt_of(squared_norm(X)) + (infinite ? g : abs_of(lambda) * g);
  const T len = sqrt_of(l2);
  const Mask<T> nonzero = len > Precision<S>::slit() * scale;
  const T zero = splat<T>(0);
  sx = nonzero ? lx / len : zero;
  sy = nonzero ? ly / len : zero;
}

/// The principal directions and the slits in 3D. Where eq. 18 is degenerate (umbilic) the slits
/// are the principal lines: slit1 along d2, slit2 along d1.
template <class T>
struct alignas(sizeof(T)) Directions {
  Vec3<T> d1, d2, slit1, slit2;
};

/// The 2D (in-plane) slits at e's two focal depths, each replaced by its principal line where it
/// vanishes; p from principal_directions(e).
template <class T>
FOCAL_HD_INLINE void slits_in_plane(const Equation<T>& e, const Principal<T>& p, T& s1x, T& s1y,
                                    T& s2x, T& s2y) {
  slit_direction(e.X, e.G, e.slit_depth1, s1x, s1y);
  slit_direction(e.X, e.G, e.slit_depth2, s2x, s2y);
  using S = Element<T>;
  const Mask<T> empty1 = s1x * s1x + s1y * s1y == S(0), empty2 = s2x * s2x + s2y * s2y == S(0);
  s1x = empty1 ? -p.d1y : s1x, s1y = empty1 ? p.d1x : s1y;
  s2x = empty2 ? p.d1x : s2x, s2y = empty2 ? p.d1y : s2y;
}

template <class T>
FOCAL_HD_INLINE Directions<T> directions_of(const Equation<T>& e) {
  const Principal<T> p = principal_directions(e);
  T s1x, s1y, s2x, s2y;
  slits_in_plane(e, p, s1x, s1y, s2x, s2y);
  const Frame<T>& f = e.frame;
  return {f.from_plane(p.d1x, p.d1y), f.from_plane(-p.d1y, p.d1x), f.from_plane(s1x, s1y),
          f.from_plane(s2x, s2y)};
}

// ---------------------------------------------------------------------------------------------
// One triplet in scalars (float on the device, float or double on the host).

/// Everything the characteristic equation gives for three rays, in world units. When `valid` is
/// false every other field is NaN.
template <class T>
struct TripletSolution {
  bool valid = false;
  T A, B, C;           ///< eq. 7 in the frame (after the sagitta correction)
  T K, H, k1, k2;      ///< K = A / C, H = B / (2 C), k1 >= k2
  T lambda1, lambda2;  ///< focal depths -1 / k1, -1 / k2 (+-inf where k = 0)
  /// |C| / s^2 with s the triplet's size (largest coordinate offset from the centroid) in float,
  /// where the positions are scaled: about the sine of the rays' triangle's smallest angle,
  /// scale-free. Small for slivers, whose M is the most sensitive to noise; the image-space
  /// window weights by it. In double (unscaled) |C| itself.
  T relative_area;
  Frame<T> frame;        ///< frame.n is the unit mean of the three normals
  Mat2<T> shape;         ///< M = G X^-1 in (frame.x, frame.y), unsymmetrised
  Vec3<T> d1, d2;        ///< unit principal directions from the symmetrised M
  Vec3<T> slit1, slit2;  ///< unit slit directions at lambda1, lambda2 (eq. 18)
};

template <class T>
FOCAL_HD TripletSolution<T> invalid_triplet() {
  TripletSolution<T> s;
  const T nan = quiet_nan<T>();
  s.A = s.B = s.C = s.K = s.H = s.k1 = s.k2 = s.lambda1 = s.lambda2 = s.relative_area = nan;
  s.frame = {nan3<T>(), nan3<T>(), nan3<T>()};
  s.shape = {nan, nan, nan, nan};
  s.d1 = s.d2 = s.slit1 = s.slit2 = nan3<T>();
  return s;
}

/// Solves the characteristic equation of the normal rays through positions p[i] along normals
/// n[i] (any length; normalised here). Invalid where a normal is zero or not finite and where
/// characteristic_equation is.
template <class T>
FOCAL_HD TripletSolution<T> solve_triplet(const Vec3<T> p[3], const Vec3<T> n[3]) {
  Vec3<T> unit[3];
  for (int i = 0; i < 3; ++i) {
    const T len = length(n[i]);
    if (!(len > T(0)) || !is_finite(len)) return invalid_triplet<T>();  // NaN fails too
    unit[i] = (T(1) / len) * n[i];
  }
  const Equation<T> e = characteristic_equation(p, unit, true);
  if (!e.valid) return invalid_triplet<T>();
  TripletSolution<T> s;
  s.valid = true;
  s.A = e.A, s.B = e.B, s.C = e.C, s.K = e.K, s.H = e.H, s.k1 = e.k1, s.k2 = e.k2;
  s.lambda1 = e.lambda1, s.lambda2 = e.lambda2;
  s.relative_area = e.relative_area;
  s.frame = e.frame;
  s.shape = {e.M.a / e.size, e.M.b / e.size, e.M.c / e.size, e.M.d / e.size};
  const Directions<T> d = directions_of(e);
  s.d1 = d.d1, s.d2 = d.d2, s.slit1 = d.slit1, s.slit2 = d.slit2;
  return s;
}

}  // namespace focal::triplet
