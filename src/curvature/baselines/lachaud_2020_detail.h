#pragma once
// Internal: LRTC20's corrected curvature measures (lachaud_2020.cpp) on given unit normals with a
// radius per vertex, for the baseline and the recommended estimator's corrected step.

#include <Eigen/Core>

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

}  // namespace focal::baselines::detail
