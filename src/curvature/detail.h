#pragma once
// Pieces shared by the per-vertex and per-triangle estimators.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/fields_detail.h"
#include "core/parallel.h"
#include "core/simd_lanes.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/normal_rays.h"
#include "focal/curvature/triangle_curvature.h"
#include "focal/mesh/neighbourhood.h"
#include "kernels/local_shape.h"

namespace focal::detail {

/// Eigenvalues k1 >= k2 of the symmetric [a b; b c], unit d1 of k1 and d2 = d1 rotated by +90
/// degrees (so that (d1, d2, n) is right-handed in a frame (x, y, n)).
struct Principal2 {
  double k1, k2;
  Eigen::Vector2d d1, d2;
};

/// kernels::principal_axes as this path has always rounded it: the operator scaled by a
/// reciprocal, the direction normalised by an exact division (kernels::Quotient). d2 is (0, 1)
/// where the operator is isotropic, not the rotation's (-0, 1): the sign of that zero shows in
/// the stored directions.
inline Principal2 principal_from_symmetric(double a, double b, double c) {
  const kernels::Principal<double> p =
      kernels::principal_axes<kernels::Quotient::reciprocal, kernels::Quotient::exact>(a, b, c);
  const Eigen::Vector2d d1(p.d1x, p.d1y);
  return {p.k1, p.k2, d1, p.isotropic ? Eigen::Vector2d(0.0, 1.0) : Eigen::Vector2d(-p.d1y, p.d1x)};
}

/// Unit copies of the rows of N; `valid[i]` is false where a row is zero or not finite.
/// Rows are independent, so any thread count gives the same result.
inline RowMatrixX3d unit_rows(NormalsRef N, std::vector<char>& valid, int threads = 0) {
  RowMatrixX3d unit(N.rows(), 3);
  valid.resize(static_cast<std::size_t>(N.rows()));
  parallel_for(N.rows(), threads, [&](std::int64_t i) {
    const double len = N.row(i).norm();
    valid[static_cast<std::size_t>(i)] = std::isfinite(len) && len > 0.0;
    unit.row(i) = N.row(i) / len;
  });
  return unit;
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

/// What the per-vertex fit reads besides the options. Split from estimate_curvature so that
/// bench/ can time the fit step alone (normals and neighbourhoods already at hand).
struct VertexFitInput {
  PositionsRef V;
  const RowMatrixX3d& unit_normals;    ///< from unit_rows
  const std::vector<char>& normal_ok;  ///< from unit_rows
  const Neighbourhoods& rings;
  double mean_edge_length;  ///< scale of the Gaussian weights and the class tolerances
};

/// The per-vertex two-slit fit of every vertex (Method::vertex); defined in curvature.cpp. The
/// closed form runs one vertex per lane, compiled for `isa` (simd_lanes.h; tests compare the
/// instruction sets, which give the same bits).
CurvatureResult fit_vertices(const VertexFitInput& in, const CurvatureOptions& options,
                             SimdIsa isa = SimdIsa::best);

/// focal::triangle_curvature with the faces solved by the lane kernel compiled for `isa`
/// (tests compare the instruction sets); defined in triangle_curvature.cpp.
TriangleCurvatureResult triangle_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options,
                                           const TriangleFields& fields, SimdIsa isa);

}  // namespace focal::detail
