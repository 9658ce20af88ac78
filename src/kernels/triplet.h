#pragma once
// The characteristic equation of three normal rays (paper sections 4.2-4.3, eqs. 5-9) in plain
// data, for nvcc and g++ alike: the one formula behind the CPU image-space estimator, the CUDA
// image-space kernel and the CUDA per-triangle kernel (and, in double, the check against
// triangle_curvature in tests/image_space_test.cpp).
//
// It follows src/curvature/triangle_curvature.cpp step by step (frame of the unit mean normal, rays
// from the centroid, sagitta correction, K = A / C, 2H = B / C, k = H +- sqrt(discriminant),
// directions from the symmetrised M = G X^-1, slits from eq. 18), with two changes for float32:
//  - positions are taken relative to the triplet's centroid and divided by the triplet's size s
//    before any product is formed, so that no intermediate over- or underflows whatever the
//    units and the results carry float's relative precision, not that of the coordinates;
//  - the discriminant is ((m00 - m11) / 2)^2 + m01 m10, which equals H^2 - K but does not cancel
//    two nearly equal squares at umbilics.
// Degeneracy tests are ratios (scale-free); their thresholds are per precision (Tolerance).

#include "kernels/host_device.h"
#include "kernels/local_shape.h"
#include "kernels/vec3.h"

namespace focal::triplet {

// The arithmetic (kernels/vec3.h) and the local shape (kernels/local_shape.h) of every kernel.
using kernels::abs_of;
using kernels::cross;
using kernels::dot;
using kernels::Frame;
using kernels::frame_of;
using kernels::is_finite;
using kernels::length;
using kernels::load3;
using kernels::max_abs;
using kernels::max_of;
using kernels::nan3;
using kernels::norm;
using kernels::Principal;
using kernels::quiet_nan;
using kernels::sqrt_of;
using kernels::store3;
using kernels::Vec3;
using kernels::vec_cast;

/// Thresholds per precision. `degenerate`: a triangle of rays whose area in the ray frame is
/// below this fraction of its squared size (|det X| vs |X|_F^2, about sin of its smallest angle)
/// has no usable shape operator; 1e-14 as the CPU path in double, 1e-5 (about 80 float epsilons,
/// the rounding of det X itself being 2 epsilons) in float. `slit`: eq. 18's slit vector counts
/// as zero (umbilic) below this fraction of its terms' size; 1e-9 as the CPU path in double,
/// 1e-5 in float, where vectors that short are rounding noise.
template <class T>
struct Tolerance;
template <>
struct Tolerance<float> {
  FOCAL_HD static float degenerate() { return 1e-5f; }
  FOCAL_HD static float slit() { return 1e-5f; }
};
template <>
struct Tolerance<double> {
  FOCAL_HD static double degenerate() { return 1e-14; }
  FOCAL_HD static double slit() { return 1e-9; }
};

// ---------------------------------------------------------------------------------------------
// 2x2 algebra.

/// [a b; c d].
template <class T>
struct Mat2 {
  T a, b, c, d;
};
template <class T>
FOCAL_HD T det(const Mat2<T>& m) {
  return m.a * m.d - m.b * m.c;
}
template <class T>
FOCAL_HD T squared_norm(const Mat2<T>& m) {
  return m.a * m.a + m.b * m.b + m.c * m.c + m.d * m.d;
}
/// G X^-1 through the adjugate of X.
template <class T>
FOCAL_HD Mat2<T> times_inverse(const Mat2<T>& g, const Mat2<T>& x) {
  const T inv = T(1) / det(x);
  return {(g.a * x.d - g.b * x.c) * inv, (g.b * x.a - g.a * x.b) * inv,
          (g.c * x.d - g.d * x.c) * inv, (g.d * x.a - g.c * x.b) * inv};
}

/// The principal axes of the symmetric [a b; b c] (kernels::principal_axes) as the triplet has
/// always rounded them: both divisions exact.
template <class T>
FOCAL_HD Principal<T> principal_of(T a, T b, T c) {
  return kernels::principal_axes<kernels::Quotient::exact, kernels::Quotient::exact>(a, b, c);
}

// ---------------------------------------------------------------------------------------------
// The characteristic equation of one triplet.

/// Everything the characteristic equation gives for three rays, in world units. When `valid` is
/// false every other field is NaN.
template <class T>
struct TripletSolution {
  bool valid = false;
  T A, B, C;           ///< eq. 7 in the frame (after the sagitta correction)
  T K, H, k1, k2;      ///< K = A / C, H = B / (2 C), k1 >= k2
  T lambda1, lambda2;  ///< focal depths -1 / k1, -1 / k2 (+-inf where k = 0)
  /// |C| / s^2 with s the triplet's size (largest coordinate offset from the centroid): about the
  /// sine of the rays' triangle's smallest angle, scale-free. Small for slivers, whose M is the
  /// most sensitive to noise; the image-space window weights by it.
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

/// Normal rays of the triplet in the frame, positions scaled by 1 / size (see solve_triplet).
template <class T>
struct ScaledRays {
  Mat2<T> X, G;    ///< columns: differences along 0->1 and 0->2 of (u, v) and (sigma, tau)
  T offset[3][2];  ///< tangential position of each point relative to the centroid
};

/// False where a ray cannot be parametrised (kernels::normal_ray, slopes divided exactly): a
/// normal outside frame.n's open hemisphere, or a ray that is not finite (its X would have no
/// area, has_area false, and the triplet be invalid all the same).
template <class T>
FOCAL_HD bool scaled_rays(const Frame<T>& f, const Vec3<T> q[3], const Vec3<T> n[3],
                          ScaledRays<T>& out) {
  T u[3], v[3], sigma[3], tau[3];
  for (int i = 0; i < 3; ++i) {
    kernels::NormalRay<T> ray;
    if (!kernels::normal_ray<kernels::Quotient::exact>(f, q[i], n[i], n[i], ray)) return false;
    sigma[i] = ray.sigma, tau[i] = ray.tau, u[i] = ray.u, v[i] = ray.v;
    out.offset[i][0] = dot(f.x, q[i]);
    out.offset[i][1] = dot(f.y, q[i]);
  }
  out.X = {u[1] - u[0], u[2] - u[0], v[1] - v[0], v[2] - v[0]};
  out.G = {sigma[1] - sigma[0], sigma[2] - sigma[0], tau[1] - tau[0], tau[2] - tau[0]};
  return true;
}

template <class T>
FOCAL_HD bool has_area(const Mat2<T>& X) {
  return abs_of(det(X)) > Tolerance<T>::degenerate() * squared_norm(X);
}

/// Re-bases the rays on the tangent plane at the surface point above the centroid: the centroid
/// lies below the surface by the sagitta (1/6) sum x_i^T S x_i (S the symmetrised M, x_i the
/// points' tangential offsets), an O(h^2) depth error that would otherwise bias K and H.
template <class T>
FOCAL_HD void correct_sagitta(ScaledRays<T>& r) {
  const Mat2<T> M0 = times_inverse(r.G, r.X);
  const T off = T(0.5) * (M0.b + M0.c);
  T sagitta = T(0);
  for (int i = 0; i < 3; ++i) {
    const T x = r.offset[i][0], y = r.offset[i][1];
    sagitta += (x * (M0.a * x + off * y) + y * (off * x + M0.d * y)) / T(6);
  }
  r.X = {r.X.a + sagitta * r.G.a, r.X.b + sagitta * r.G.b, r.X.c + sagitta * r.G.c,
         r.X.d + sagitta * r.G.d};
}

/// Unit slit direction (2D) at scaled focal depth lambda from eq. 18, along whichever edge gives
/// the longer vector; (0, 0) where both vanish (umbilic: all three rays meet in one point).
template <class T>
FOCAL_HD void slit_direction(const Mat2<T>& X, const Mat2<T>& G, T lambda, T& sx, T& sy) {
  const bool at_infinity = !is_finite(lambda);
  T ax = X.a + lambda * G.a, ay = X.c + lambda * G.c;
  T bx = X.b + lambda * G.b, by = X.d + lambda * G.d;
  if (at_infinity) ax = G.a, ay = G.c, bx = G.b, by = G.d;  // the direction's limit
  const bool a_longer = ax * ax + ay * ay >= bx * bx + by * by;
  const T lx = a_longer ? ax : bx, ly = a_longer ? ay : by;
  const T g = sqrt_of(squared_norm(G));
  const T scale = sqrt_of(squared_norm(X)) + (at_infinity ? g : abs_of(lambda) * g);
  const T len = sqrt_of(lx * lx + ly * ly);
  const bool nonzero = len > Tolerance<T>::slit() * scale;
  sx = nonzero ? lx / len : T(0);
  sy = nonzero ? ly / len : T(0);
}

/// Principal curvatures, directions and slits from the corrected scaled rays; `size` is the
/// scale s the positions were divided by (curvatures scale by 1/s, lengths by s). K and C are
/// formed as (K' / s) / s and (C' s) s: they overflow only where the true value is beyond T.
template <class T>
FOCAL_HD TripletSolution<T> solve_scaled(const Frame<T>& f, const ScaledRays<T>& r, T size) {
  const Mat2<T>& X = r.X;
  const Mat2<T>& G = r.G;
  const T A = det(G);
  const T B = G.a * X.d - G.b * X.c - G.c * X.b + G.d * X.a;
  const T C = det(X);
  const Mat2<T> M = times_inverse(G, X);
  const T half_gap = T(0.5) * (M.a - M.d);
  // Below zero only through rounding or an unsymmetric M (noise): the double root H, as the CPU.
  // max_of(0, x), not (x, 0): NaN (an M that overflowed) gives 0 here, as it always has.
  const T root = sqrt_of(max_of(T(0), half_gap * half_gap + M.b * M.c));
  const T H = B / (T(2) * C);
  TripletSolution<T> s;
  s.valid = true;
  s.A = A, s.B = B * size, s.C = C * size * size;
  s.K = A / C / size / size, s.H = H / size;
  s.k1 = (H + root) / size, s.k2 = (H - root) / size;
  s.lambda1 = T(-1) / s.k1, s.lambda2 = T(-1) / s.k2;
  s.relative_area = abs_of(C);
  s.frame = f;
  s.shape = {M.a / size, M.b / size, M.c / size, M.d / size};
  const Principal<T> p = principal_of(M.a, T(0.5) * (M.b + M.c), M.d);
  s.d1 = f.from_plane(p.d1x, p.d1y);
  s.d2 = f.from_plane(-p.d1y, p.d1x);
  // Where eq. 18 is degenerate (umbilic) the slits are the principal lines: slit1 along d2.
  T sx, sy;
  slit_direction(X, G, T(-1) / (H + root), sx, sy);
  s.slit1 = (sx != T(0) || sy != T(0)) ? f.from_plane(sx, sy) : s.d2;
  slit_direction(X, G, T(-1) / (H - root), sx, sy);
  s.slit2 = (sx != T(0) || sy != T(0)) ? f.from_plane(sx, sy) : s.d1;
  return s;
}

/// Solves the characteristic equation of the normal rays through positions p[i] along normals
/// n[i] (any length; normalised here). Invalid where a normal is zero or not finite, the three
/// normals do not share a hemisphere with their mean, the points coincide or the rays' triangle
/// has no area. The order of the points (the triplet's orientation) does not matter: swapping two
/// flips the signs of A, B, C together.
template <class T>
FOCAL_HD TripletSolution<T> solve_triplet(const Vec3<T> p[3], const Vec3<T> n[3]) {
  Vec3<T> unit[3];
  for (int i = 0; i < 3; ++i) {
    const T len = length(n[i]);
    if (!(len > T(0)) || !is_finite(len)) return invalid_triplet<T>();  // NaN fails too
    unit[i] = (T(1) / len) * n[i];
  }
  const Vec3<T> sum = unit[0] + unit[1] + unit[2];
  const T len = norm(sum);  // at most 3: no overflow
  if (!(len > T(0))) return invalid_triplet<T>();
  const Frame<T> f = frame_of((T(1) / len) * sum);
  // Centroid-relative and divided by the triplet's size s (largest coordinate offset from the
  // centroid, no squares formed): X = O(1) and G = O(h k) whatever the units and the position,
  // so float keeps its relative precision from here on.
  const Vec3<T> centroid = (T(1) / T(3)) * (p[0] + p[1] + p[2]);
  Vec3<T> q[3];
  T size = T(0);
  for (int i = 0; i < 3; ++i) {
    q[i] = p[i] - centroid;
    if (!is_finite(q[i])) return invalid_triplet<T>();  // a NaN or infinite position
    size = max_of(size, max_abs(q[i]));
  }
  if (!(size > T(0))) return invalid_triplet<T>();
  for (int i = 0; i < 3; ++i) q[i] = (T(1) / size) * q[i];
  ScaledRays<T> rays;
  if (!scaled_rays(f, q, unit, rays) || !has_area(rays.X)) return invalid_triplet<T>();
  correct_sagitta(rays);
  if (!has_area(rays.X)) return invalid_triplet<T>();
  return solve_scaled(f, rays, size);
}

}  // namespace focal::triplet
