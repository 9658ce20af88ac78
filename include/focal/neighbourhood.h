#pragma once
/// \file neighbourhood.h
/// Vertex neighbourhoods in compressed sparse row (CSR) form: the neighbours of vertex i are
/// `indices[offsets[i] .. offsets[i+1])`. Manifold connectivity is not required.

#include <vector>

#include "focal/mesh.h"

namespace focal {

/// CSR lists, one per vertex.
struct Neighbourhoods {
  Eigen::VectorXi offsets;  ///< #V + 1, offsets[0] = 0
  Eigen::VectorXi indices;  ///< concatenated neighbour lists

  [[nodiscard]] int vertex_count() const { return static_cast<int>(offsets.size()) - 1; }
  [[nodiscard]] int size(int i) const { return offsets[i + 1] - offsets[i]; }
  [[nodiscard]] const int* begin(int i) const { return indices.data() + offsets[i]; }
  [[nodiscard]] const int* end(int i) const { return indices.data() + offsets[i + 1]; }
};

/// 1-ring: for each vertex the vertices sharing an edge with it, sorted ascending, no duplicates,
/// never the vertex itself (degenerate faces with repeated indices add no self-loops).
/// \throw InvalidInput when F indexes outside [0, vertex_count).
[[nodiscard]] Neighbourhoods vertex_adjacency(int vertex_count, FacesRef F);

/// k-ring: all vertices within k edges (k >= 1), excluding the vertex itself, each once, sorted
/// by ring distance then by index. k = 1 returns a copy of `one_ring`.
/// \throw InvalidInput when k < 1.
[[nodiscard]] Neighbourhoods k_ring(const Neighbourhoods& one_ring, int k);

/// #V flags: true for vertices on a boundary edge (an edge with exactly one incident face).
[[nodiscard]] std::vector<bool> boundary_vertices(int vertex_count, FacesRef F);

/// Per-vertex ring distance to the nearest boundary vertex (0 on the boundary), capped at
/// `max_rings` + 1 for vertices farther away or in components without boundary.
[[nodiscard]] Eigen::VectorXi rings_to_boundary(const Neighbourhoods& one_ring,
                                                const std::vector<bool>& boundary, int max_rings);

/// Counts that describe the connectivity and quality of a mesh (for `focal info`).
struct MeshStatistics {
  int vertex_count = 0;
  int face_count = 0;
  int edge_count = 0;                ///< undirected edges
  int boundary_edge_count = 0;       ///< edges with one incident face
  int non_manifold_edge_count = 0;   ///< edges with three or more incident faces
  int non_manifold_vertex_count = 0; ///< vertices whose incident faces form more than one fan
  int unreferenced_vertex_count = 0; ///< vertices in no face
  int degenerate_face_count = 0;     ///< repeated indices or zero area
  int duplicate_face_count = 0;      ///< same vertex set as an earlier face
  int component_count = 0;           ///< connected components of faces
  Eigen::Vector3d min_corner{0, 0, 0};
  Eigen::Vector3d max_corner{0, 0, 0};
  double mean_edge_length = 0.0;
};

[[nodiscard]] MeshStatistics mesh_statistics(PositionsRef V, FacesRef F);

}  // namespace focal
