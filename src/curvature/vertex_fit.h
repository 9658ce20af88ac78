#pragma once
// Internal: the per-vertex two-slit fit of curvature.cpp, for the recommended estimator, the
// tests and the benchmarks (which time the fit step alone).

#include <vector>

#include "core/simd_lanes.h"
#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/prepared.h"

namespace focal::detail {

/// What the per-vertex fit reads besides the options. Split from estimate_curvature so that
/// bench/ can time the fit step alone (normals and neighbourhoods already at hand).
struct VertexFitInput {
  PositionsRef V;
  const RowMatrixX3d& unit_normals;    ///< from unit_rows
  const std::vector<char>& normal_ok;  ///< from unit_rows
  const Neighbourhoods& rings;
  double mean_edge_length;  ///< scale of the Gaussian weights and the class tolerances
};

/// The per-vertex two-slit fit of every vertex (Method::vertex). The closed form runs one vertex
/// per lane, compiled for `isa` (simd_lanes.h; tests compare the instruction sets, which give
/// the same bits).
CurvatureResult fit_vertices(const VertexFitInput& in, const CurvatureOptions& options,
                             SimdIsa isa = SimdIsa::best);

/// The roughness of the closed-form fit of every vertex: its residual (RMS ray misfit, slope
/// units, the bits of fit_vertices' residual) where the fit is valid and every neighbour gave a
/// ray, NaN elsewhere (a normal more than 90 degrees from the vertex's, as a flipped or wild
/// normal makes it, leaves a ray out; the residual of the few left says nothing then). Writes
/// one array, not fit_vertices' ten: the recommended estimator rates normal fields by it.
Eigen::VectorXd fit_roughness(const VertexFitInput& in, const CurvatureOptions& options,
                              SimdIsa isa = SimdIsa::best);

/// fit_roughness of the `count` listed vertices only (entry k: vertex vertices[k]), the same
/// bits: a lane's sums do not depend on the other vertices of its group.
Eigen::VectorXd fit_roughness_at(const VertexFitInput& in, const CurvatureOptions& options,
                                 const int* vertices, Eigen::Index count,
                                 SimdIsa isa = SimdIsa::best);

/// Throws InvalidInput for CurvatureOptions out of range (estimate_curvature's check).
void validate_curvature_options(const CurvatureOptions& options);

/// estimate_curvature's per-vertex fit (Method::vertex) on a mesh with normals, with its 1-ring
/// at hand; the options already validated.
CurvatureResult vertex_curvature_from_rays(const PreparedMesh& mesh, const Neighbourhoods& one_ring,
                                           const CurvatureOptions& options);

}  // namespace focal::detail
