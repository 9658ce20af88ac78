#pragma once
// A vertex's row of a CurvatureResult from its fit, as every estimator writes it: the principal
// curvatures and directions of the fitted operator, classified with the mesh's tolerances, and
// the rows left undefined where estimated normals say nothing (isolated triangles).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/result_rows.h"
#include "core/simd_lanes.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/normal_rays.h"
#include "focal/mesh/neighbourhood.h"
#include "kernels/local_shape.h"
#include "mesh/prepared_access.h"  // unit_rows

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

/// Thresholds of the classification in absolute curvature units for a mesh of edge length h.
struct ClassTolerances {
  double zero = 0.0;     ///< |k| at or below this is zero
  double umbilic = 0.0;  ///< relative k1 - k2 gap at or below this is umbilic
};

inline ClassTolerances class_tolerances(const CurvatureOptions& options, double edge_length) {
  return {options.tolerances.zero / edge_length, options.tolerances.umbilic};
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

/// Vertices of isolated triangles (each corner in no other face) get `undefined` when their
/// normals were estimated: all three normals are then the one face normal, so any fit returns
/// k1 = k2 = 0 (`flat`) whatever the surface was (an STL read with --no-weld is all such
/// triangles). With normals from the file the rays differ and the fit stands.
inline void undefine_isolated_triangles(FacesRef F, CurvatureResult& r) {
  std::vector<std::uint8_t> faces_at(static_cast<std::size_t>(r.k1.size()), 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      std::uint8_t& n = faces_at[static_cast<std::size_t>(F(f, c))];
      n = static_cast<std::uint8_t>(std::min(n + 1, 2));
    }
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    bool isolated = true;
    for (int c = 0; c < 3; ++c) isolated &= faces_at[static_cast<std::size_t>(F(f, c))] == 1;
    if (!isolated) continue;
    for (int c = 0; c < 3; ++c) detail::store_undefined(r, F(f, c));
  }
}

}  // namespace focal::detail
