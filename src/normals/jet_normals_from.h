#pragma once
// Internal: the jets of jets.cpp with their inputs at hand, for the recommended estimator.

#include <optional>
#include <vector>

#include "core/simd_lanes.h"
#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/jets.h"

namespace focal::detail {

/// jet_normals of the mesh whose positions are V and 1-ring `one_ring`, the first fit of each
/// vertex in the frame of `start`, whose rows must be unit or non-finite (not checked: Max's
/// normals are, by construction). The fits run side by side
/// in the lanes of `isa`'s kernel (the same bits for every instruction set); std::nullopt: one
/// vertex at a time, the reference the lanes are tested against. `sort_rows`: null, or V and
/// one_ring are a permuted copy of a cloud (copy row j is cloud row (*sort_rows)[j]; a cloud's
/// spatial copy, curvature/cloud_curvature.cpp): each jet's points are then summed in the order
/// of their rows in the cloud, as the fit of the cloud itself sums them (in ascending index),
/// so that the copy's jets have the cloud's bits.
/// \throw InvalidInput when an option is out of range, one_ring does not have #V vertices or
/// sort_rows does not have #V rows.
JetNormals jet_normals_from(PositionsRef V, const Neighbourhoods& one_ring, NormalsRef start,
                            const JetOptions& options, std::optional<SimdIsa> isa = SimdIsa::best,
                            const std::vector<int>* sort_rows = nullptr);

/// The residuals (JetNormals::residual) of the jets of the listed vertices only, as
/// jet_normals_from computes them: for measurements on a sample of the vertices.
Eigen::VectorXd jet_residuals_at(PositionsRef V, const Neighbourhoods& one_ring, NormalsRef start,
                                 const JetOptions& options, const std::vector<int>& vertices);

/// jet_normals_from at the listed vertices only (row k: vertex vertices[k]; the same bits).
JetNormals jet_normals_at(PositionsRef V, const Neighbourhoods& one_ring, NormalsRef start,
                          const JetOptions& options, const std::vector<int>& vertices,
                          std::optional<SimdIsa> isa = SimdIsa::best);

}  // namespace focal::detail
