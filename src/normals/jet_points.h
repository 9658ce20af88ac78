#pragma once
// Internal: a vertex's jet points (normals/jet_points.cpp) for normals/jets.cpp: the vertices
// within a few edges of it, gathered in ascending order, and their coordinates in its tangent
// frame, scaled to the unit ball.

#include <cstdint>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"
#include "kernels/local_shape.h"
#include "mesh/topology.h"
#include "normals/jet_fit.h"

namespace focal::detail::jets {

/// The vertices within `rings` edges of v (v included), sorted, into `ring`: breadth-first over
/// the 1-ring with marks (`in_ring`: one bit per vertex, allocated on first use, #V / 8 bytes: it
/// stays in cache; set while the vertex is in the neighbourhood being gathered, cleared after
/// it), then sorted so that the points, and hence the sums of the fit, come in ascending index
/// order whatever order the search visited them in. `sort_rows`: null, or the vertices are a
/// permuted copy's, sorted by their rows in the cloud (sort_rows[w]) so that the sums keep the
/// cloud's order (jet_normals_from).
void gather_ring(const Neighbourhoods& one, int v, int rings, std::vector<std::uint64_t>& in_ring,
                 const std::vector<int>* sort_rows, std::vector<int>& ring);

/// A vertex's points: resize() leaves new entries unwritten (gather_points writes them).
using Points = std::vector<Point, detail::DefaultInitAllocator<Point>>;

/// The vertex itself (zero) and its ring in the frame, scaled by the largest offset, into
/// `points`; non-finite neighbours are skipped. Returns the scale (0 when no usable neighbour).
double gather_points(PositionsRef V, int i, const kernels::Frame<double>& f,
                     const std::vector<int>& ring, Points& points);

}  // namespace focal::detail::jets
