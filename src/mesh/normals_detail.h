#pragma once
// Internal: the parts of normals.cpp that check.cpp and statistics.cpp reuse with a connectivity
// they have already computed.

#include <optional>

#include "core/simd_lanes.h"
#include "focal/core/mesh.h"
#include "focal/mesh/normals.h"
#include "mesh/statistics_detail.h"
#include "mesh/topology.h"

namespace focal::detail {

/// orientation_report from a topology already computed for (V, F).
OrientationReport orientation_report_from(PositionsRef V, FacesRef F, const MeshTopology& t,
                                          int threads);

/// vertex_normals from an incidence already computed for F. The area and Max weightings run
/// several vertices side by side in the lanes of `isa` (the same bits for every instruction set);
/// std::nullopt: one vertex at a time, the reference the lanes are tested against.
RowMatrixX3d vertex_normals_from(PositionsRef V, FacesRef F, const VertexFaces& inc,
                                 NormalWeighting weighting, int threads,
                                 std::optional<SimdIsa> isa = SimdIsa::best);

}  // namespace focal::detail
