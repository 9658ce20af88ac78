#pragma once
// Internal: the 1-ring of neighbourhood.cpp from an incidence at hand (a PreparedMesh's).

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"
#include "mesh/topology.h"

namespace focal::detail {

/// vertex_adjacency(inc.vertex_count(), F) from the incidence of F.
/// \throw InvalidInput when the lists would not fit 32-bit offsets.
Neighbourhoods vertex_adjacency_from(const VertexFaces& inc, FacesRef F, int threads);

}  // namespace focal::detail
