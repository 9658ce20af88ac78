#pragma once
/// \file neighbourhood.h
/// Vertex neighbourhoods in compressed sparse row (CSR) form: the neighbours of vertex i are
/// `indices[offsets[i] .. offsets[i+1])`. Manifold connectivity is not required.
///
/// Edge conventions (shared with orientation.h): an edge is a pair of distinct vertices that are
/// corners of a common face; its incident faces are the faces having both as corners, each once
/// (also a face with a repeated index, such as (a, a, b) for the edge {a, b}).
///
/// All functions gather per vertex in a fixed order: results do not depend on the thread count
/// (that of the current ExecutionScope, focal/core/execution.h).

#include <vector>

#include "focal/core/mesh.h"

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
/// \throw InvalidInput when vertex_count < 0, F indexes outside [0, vertex_count), or the lists
/// would not fit 32-bit offsets.
[[nodiscard]] Neighbourhoods vertex_adjacency(int vertex_count, FacesRef F);

/// The most vertices a neighbourhood of two or more rings may hold (the vertex itself not
/// counted). A vertex with more within its rings, such as every corner of a polygon of thousands
/// of corners (fan-triangulated on read: the fan's hub neighbours them all) or of the faces around
/// an edge shared by thousands of faces, gets an empty neighbourhood from k_ring() and from the
/// jets (jets.h), so the estimators leave it `undefined` rather than fit an arbitrary part of
/// it; the search stops at the cap, so a run costs O(#V x cap) at worst instead of O(#V^2).
/// Ordinary meshes stay far below it: a 4-ring (the widest the recommended estimator uses) holds
/// 60 vertices on a regular valence-6 grid.
/// 1-rings are never capped (together they hold twice the edges: linear already).
inline constexpr int kMaxNeighbourhoodSize = 1024;

/// k-ring: all vertices within k edges (k >= 1), excluding the vertex itself, each once, sorted
/// by ring distance then by index. k = 1 returns a copy of `one_ring`. For k >= 2 a vertex with
/// more than kMaxNeighbourhoodSize vertices within k edges gets an empty list
/// (crowded_vertices() names them).
/// \throw InvalidInput when k < 1, `one_ring` is not a valid CSR (offsets not starting at 0,
/// decreasing, not ending at indices.size(), or an index outside [0, #V)), or the result would
/// not fit 32-bit offsets.
[[nodiscard]] Neighbourhoods k_ring(const Neighbourhoods& one_ring, int k);

/// The vertices (ascending) whose k-ring has more than kMaxNeighbourhoodSize vertices, those
/// k_ring() leaves empty; none for k = 1. O(#V x kMaxNeighbourhoodSize) at most.
/// \throw InvalidInput as k_ring().
[[nodiscard]] std::vector<int> crowded_vertices(const Neighbourhoods& one_ring, int k);

/// #V flags: true for vertices on a boundary edge (an edge with exactly one incident face).
/// Vertices only on non-manifold edges (3+ faces) are not boundary vertices.
/// \throw InvalidInput when vertex_count < 0 or F indexes outside [0, vertex_count).
[[nodiscard]] std::vector<bool> boundary_vertices(int vertex_count, FacesRef F);

/// Per-vertex ring distance to the nearest boundary vertex (0 on the boundary), capped at
/// `max_rings` + 1 for vertices farther away or in components without boundary.
/// \throw InvalidInput when `one_ring` is not a valid CSR, boundary.size() != #V, or
/// max_rings < 0 or max_rings + 1 overflows int.
[[nodiscard]] Eigen::VectorXi rings_to_boundary(const Neighbourhoods& one_ring,
                                                const std::vector<bool>& boundary, int max_rings);

/// Counts that describe the connectivity and quality of a mesh (for `focal info`).
struct MeshStatistics {
  int vertex_count = 0;
  int face_count = 0;
  int edge_count = 0;                   ///< undirected edges
  int boundary_edge_count = 0;          ///< edges with one incident face
  int non_manifold_edge_count = 0;      ///< edges with three or more incident faces
  int non_manifold_vertex_count = 0;    ///< vertices whose incident faces form more than one fan
                                        ///< (faces are in one fan when linked through edges at
                                        ///< the vertex; e.g. the tip of a bowtie). Faces with a
                                        ///< repeated index are left out.
  int unreferenced_vertex_count = 0;    ///< vertices in no face
  int degenerate_face_count = 0;        ///< repeated indices or zero area: |cross| <= 1e-14 L^2,
                                        ///< L the longest edge (scale invariant)
  int duplicate_face_count = 0;         ///< same vertex set as an earlier face (any order)
  int component_count = 0;              ///< connected components of faces (sharing a vertex)
  Eigen::Vector3d min_corner{0, 0, 0};  ///< bounding box of all of V (zero when V is empty)
  Eigen::Vector3d max_corner{0, 0, 0};
  double mean_edge_length = 0.0;  ///< focal::mean_edge_length (per face, so interior edges twice)
};

/// Counts of the mesh's connectivity and quality; linear time, parallel per vertex.
/// \throw InvalidInput when F indexes outside V.
[[nodiscard]] MeshStatistics mesh_statistics(PositionsRef V, FacesRef F);

}  // namespace focal
