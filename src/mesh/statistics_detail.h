#pragma once
// Internal: the connectivity pass of statistics.cpp, shared with orientation.cpp
// (orientation_report) and check.cpp (check_mesh).

#include <cstdint>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"
#include "mesh/topology.h"

namespace focal::detail {

/// Edge findings of one vertex for its edges to higher-indexed neighbours (each edge once).
enum EdgeFlag : std::uint8_t {
  kOpenEdge = 1,          ///< an edge without exactly two incident faces
  kInconsistentEdge = 2,  ///< an interior edge traversed the same way by both faces
};

/// What mesh_statistics, orientation_report and check_mesh need of the connectivity beyond the
/// incidence, computed in one parallel pass over the vertices' edge sides (each was a pass of its
/// own before).
struct MeshTopology {
  FaceComponents components;
  std::vector<std::uint8_t> edge_flags;  ///< #V, EdgeFlag bits
  std::int64_t edge_count = 0;
  std::int64_t boundary_edge_count = 0;
  std::int64_t non_manifold_edge_count = 0;
  std::int64_t non_manifold_vertex_count = 0;
  std::int64_t duplicate_face_count = 0;
  std::int64_t unreferenced_vertex_count = 0;
};

/// How much of MeshTopology to compute: `orientation` leaves out the fans (non-manifold
/// vertices) and duplicate faces, which orientation_report does not need.
enum class TopologyDetail { orientation, statistics };

/// The topology of F from its incidence `inc` (vertex_face_incidence of F, whose vertex count is
/// the mesh's). With `one_ring`, also writes the 1-ring there (vertex_adjacency_from's lists,
/// from the same sorted edge sides).
MeshTopology mesh_topology(const VertexFaces& inc, FacesRef F, TopologyDetail detail, int threads,
                           Neighbourhoods* one_ring = nullptr);

/// Counts of the faces that span no triangle.
struct DegenerateFaces {
  std::int64_t repeated_index = 0;  ///< faces with a repeated index (has_repeated_index)
  std::int64_t zero_area = 0;  ///< the others of numerically zero area (is_degenerate_triangle)
};

/// DegenerateFaces of F in one parallel pass. F must already be validated against V.
DegenerateFaces degenerate_faces(PositionsRef V, FacesRef F, int threads);

}  // namespace focal::detail
