#pragma once
// Internal: LRTC20's corrected curvature measures (lachaud_2020.cpp) on given unit normals with a
// radius per vertex, for the baseline and the recommended estimator's corrected step.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "curvature/vertex_rows.h"
#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"
#include "focal/mesh/prepared.h"

namespace focal::baselines::detail {

/// LRTC20 (focal::baselines::lachaud_2020) at every vertex i with radius[i] > 0, its ball capped
/// at `max_rings` edges from i (ball::gather); vertices with radius[i] <= 0 or no normal are
/// left undefined. `u`: #V x 3 unit normals, NaN rows where there is none.
CurvatureResult corrected_curvature(const PreparedMesh& mesh, const RowMatrixX3d& u,
                                    const Eigen::VectorXd& radius, int max_rings,
                                    const CurvatureOptions& options);

/// The same at vertex i alone over the listed faces (corners into V and u; each weighted by its
/// fraction inside the ball of radius r about V.row(i)) instead of the mesh's ball: a cloud
/// point's local triangulation (curvature/cloud_curvature.cpp). Writes row i of `result`;
/// leaves it as it is where u.row(i) is not finite, r is not positive or the faces' area inside
/// the ball is not positive.
void corrected_curvature_of_faces(PositionsRef V, const RowMatrixX3d& u,
                                  const std::vector<std::array<int, 3>>& faces, std::int64_t i,
                                  double r, const focal::detail::ClassTolerances& tol,
                                  CurvatureResult& result);

}  // namespace focal::baselines::detail
