#pragma once
// Pieces shared by the per-vertex and per-triangle estimators.

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <vector>

#include "focal/curvature.h"
#include "focal/normal_rays.h"

namespace focal::detail {

/// Eigenvalues k1 >= k2 of the symmetric [a b; b c], unit d1 of k1 and d2 = d1 rotated by +90
/// degrees (so that (d1, d2, n) is right-handed in a frame (x, y, n)).
struct Principal2 {
  double k1, k2;
  Eigen::Vector2d d1, d2;
};

inline Principal2 principal_from_symmetric(double a, double b, double c) {
  const double mean = 0.5 * (a + c);
  const double half_gap = std::hypot(0.5 * (a - c), b);
  const double phi = 0.5 * std::atan2(2.0 * b, a - c);  // angle of d1; 0 when isotropic
  const Eigen::Vector2d d1(std::cos(phi), std::sin(phi));
  return {mean + half_gap, mean - half_gap, d1, Eigen::Vector2d(-d1.y(), d1.x())};
}

/// Unit copies of the rows of N; `valid[i]` is false where a row is zero or not finite.
inline RowMatrixX3d unit_rows(NormalsRef N, std::vector<char>& valid) {
  RowMatrixX3d unit(N.rows(), 3);
  valid.assign(static_cast<std::size_t>(N.rows()), 0);
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const double len = N.row(i).norm();
    valid[static_cast<std::size_t>(i)] = std::isfinite(len) && len > 0.0;
    unit.row(i) = N.row(i) / len;
  }
  return unit;
}

/// A result of n vertices, every one `undefined` with NaN fields until it is filled.
inline CurvatureResult undefined_result(Eigen::Index n) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CurvatureResult r;
  r.k1 = r.k2 = r.H = r.K = r.residual = Eigen::VectorXd::Constant(n, nan);
  r.d1 = r.d2 = RowMatrixX3d::Constant(n, 3, nan);
  r.point_class = VectorXu8::Constant(n, static_cast<std::uint8_t>(PointClass::undefined));
  r.rays_used = r.rays_excluded = Eigen::VectorXi::Zero(n);
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
