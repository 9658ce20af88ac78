#pragma once
// Pieces shared by the per-vertex and per-triangle estimators.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/parallel.h"
#include "core/simd_lanes.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/normal_rays.h"
#include "focal/mesh/neighbourhood.h"
#include "mesh/prepared_detail.h"  // unit_rows

namespace focal::detail {

/// Eigenvalues k1 >= k2 of the symmetric [a b; b c], unit d1 of k1 and d2 = d1 rotated by +90
/// degrees (so that (d1, d2, n) is right-handed in a frame (x, y, n)).
struct Principal2 {
  double k1, k2;
  Eigen::Vector2d d1, d2;
};

inline Principal2 principal_from_symmetric(double a, double b, double c) {
  const double mean = 0.5 * (a + c);
  const double d = 0.5 * (a - c);
  // In units of s = max(|d|, |b|) squares neither overflow nor underflow, as with std::hypot;
  // with the algebraic eigenvector below this avoids hypot, atan2 and sincos, which were a
  // quarter of the per-vertex fit's time.
  const double s = std::max(std::abs(d), std::abs(b));
  if (s == 0.0) return {mean, mean, {1.0, 0.0}, {0.0, 1.0}};  // isotropic: any frame, take x
  const double inv = 1.0 / s;
  const double ds = d * inv, bs = b * inv;
  const double r = std::sqrt(ds * ds + bs * bs);  // half the eigenvalue gap, over s
  // The eigenvector of k1 with angle in (-pi/2, pi/2]: (r + d, b), or where that cancels
  // (d < 0) the parallel (b, r - d) turned to x >= 0. Both have length sqrt(2 r (r + |d|)).
  Eigen::Vector2d d1 = ds >= 0.0 ? Eigen::Vector2d(r + ds, bs)
                                 : Eigen::Vector2d(std::abs(bs), std::copysign(r - ds, bs));
  d1 /= std::sqrt(2.0 * r * (r + std::abs(ds)));
  return {mean + s * r, mean - s * r, d1, Eigen::Vector2d(-d1.y(), d1.x())};
}

/// A result of n vertices with every field allocated but not written: the caller writes each
/// row once, with store_vertex or store_undefined, from the thread that owns it (first touch
/// then happens in parallel, and nothing is written twice).
inline CurvatureResult unwritten_result(Eigen::Index n) {
  CurvatureResult r;
  for (Eigen::VectorXd* v : {&r.k1, &r.k2, &r.H, &r.K, &r.residual}) v->resize(n);
  r.d1.resize(n, 3);
  r.d2.resize(n, 3);
  r.point_class.resize(n);
  r.rays_used.resize(n);
  r.rays_excluded.resize(n);
  for (Eigen::VectorXd* v : {&r.k1, &r.k2, &r.H, &r.K, &r.residual}) {
    advise_huge_pages(v->data(), sizeof(double) * static_cast<std::size_t>(n));
  }
  for (RowMatrixX3d* d : {&r.d1, &r.d2}) {
    advise_huge_pages(d->data(), 3 * sizeof(double) * static_cast<std::size_t>(n));
  }
  return r;
}

/// Marks vertex i `undefined`: NaN in every numeric field. Leaves the ray counts alone.
inline void store_undefined(CurvatureResult& r, Eigen::Index i) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.k1[i] = r.k2[i] = r.H[i] = r.K[i] = r.residual[i] = nan;
  r.d1.row(i).setConstant(nan);
  r.d2.row(i).setConstant(nan);
  r.point_class[i] = static_cast<std::uint8_t>(PointClass::undefined);
}

/// A result of n vertices, every one `undefined` with NaN fields until it is filled.
inline CurvatureResult undefined_result(Eigen::Index n, int threads = 0) {
  CurvatureResult r = unwritten_result(n);
  parallel_for(n, threads, [&](std::int64_t i) {
    store_undefined(r, i);
    r.rays_used[i] = r.rays_excluded[i] = 0;
  });
  return r;
}

/// Thresholds of the classification in absolute curvature units for a mesh of edge length h.
struct ClassTolerances {
  double zero = 0.0;     ///< |k| at or below this is zero
  double umbilic = 0.0;  ///< relative k1 - k2 gap at or below this is umbilic
};

inline ClassTolerances class_tolerances(const CurvatureOptions& options, double edge_length) {
  return {options.zero_tolerance / edge_length, options.umbilic_tolerance};
}

/// Stores one vertex's principal curvatures and directions (2D in `frame`).
inline void store_vertex(CurvatureResult& r, Eigen::Index i, const TangentFrame& frame,
                         const Principal2& p, double residual, const ClassTolerances& tol) {
  r.k1[i] = p.k1;
  r.k2[i] = p.k2;
  r.H[i] = 0.5 * (p.k1 + p.k2);
  r.K[i] = p.k1 * p.k2;
  r.d1.row(i) = frame.from_plane(p.d1);
  r.d2.row(i) = frame.from_plane(p.d2);
  r.residual[i] = residual;
  r.point_class[i] = static_cast<std::uint8_t>(classify(p.k1, p.k2, tol.zero, tol.umbilic));
}

}  // namespace focal::detail
