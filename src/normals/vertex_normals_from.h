#pragma once
// vertex_normals on an incidence already at hand (a PreparedMesh's, check_mesh's, a cloud
// point's local fan), with the lane instruction set to use: for the mesh check, the estimators'
// normals and the tests of the lanes.

#include <optional>

#include "core/simd_lanes.h"
#include "focal/core/mesh.h"
#include "focal/normals/vertex_normals.h"
#include "mesh/topology.h"

namespace focal::detail {

/// vertex_normals from an incidence already computed for F. The area and Max weightings run
/// several vertices side by side in the lanes of `isa` (the same bits for every instruction set);
/// std::nullopt: one vertex at a time, the reference the lanes are tested against.
RowMatrixX3d vertex_normals_from(PositionsRef V, FacesRef F, const VertexFaces& inc,
                                 NormalWeighting weighting, int threads,
                                 std::optional<SimdIsa> isa = SimdIsa::best);

}  // namespace focal::detail
