#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "focal/neighbourhood.h"
#include "parallel.h"
#include "topology_incidence.h"

namespace focal {
namespace {

// What one vertex contributes to the counts: edges to higher-indexed neighbours (so each edge is
// counted once), duplicate faces whose smallest index it is (so each face is examined once).
struct VertexCounts {
  int edges = 0;
  int boundary_edges = 0;
  int non_manifold_edges = 0;
  int duplicate_faces = 0;
  bool non_manifold_vertex = false;
};

struct Scratch {
  std::vector<detail::EdgeSide> sides;
  std::vector<int> fan_parent;
  std::vector<std::array<int, 3>> triples;  // (middle, largest index, face) of faces at v
};

// Number of fans at v: its incident faces joined whenever they share an edge at v. Faces with a
// repeated index span no wedge at v (a face (v, v, v) has no edge at all), so they neither form
// nor link fans.
int fan_count(FacesRef F, const detail::VertexFaces& inc, std::int64_t v,
              const std::vector<detail::EdgeSide>& sides, std::vector<int>& parent) {
  const int face_count = inc.size(v);
  parent.resize(static_cast<std::size_t>(face_count));
  for (int i = 0; i < face_count; ++i) parent[static_cast<std::size_t>(i)] = i;
  const auto proper = [&](int local_face) {
    return !detail::has_repeated_index(
        F, inc.faces[static_cast<std::size_t>(inc.begin(v) + local_face)]);
  };
  detail::for_each_edge(sides,
                        [&](int, const detail::EdgeSide* first, const detail::EdgeSide* last) {
                          const detail::EdgeSide* anchor = nullptr;
                          for (const auto* s = first; s < last; ++s) {
                            if (!proper(s->local_face)) continue;
                            if (anchor) detail::unite(parent, anchor->local_face, s->local_face);
                            if (!anchor) anchor = s;
                          }
                        });
  int fans = 0;
  for (int i = 0; i < face_count; ++i) {
    fans += proper(i) && detail::find_root(parent, i) == i ? 1 : 0;
  }
  return fans;
}

// Faces whose sorted index triple starts with v and repeats that of an earlier face.
int duplicate_faces_at(FacesRef F, const detail::VertexFaces& inc, std::int64_t v,
                       std::vector<std::array<int, 3>>& triples) {
  triples.clear();
  for (int j = inc.begin(v); j < inc.end(v); ++j) {
    const int f = inc.faces[static_cast<std::size_t>(j)];
    std::array<int, 3> t{F(f, 0), F(f, 1), F(f, 2)};
    std::sort(t.begin(), t.end());
    if (t[0] == v) triples.push_back({t[1], t[2], f});
  }
  // Sorting by face last puts the earliest face of each vertex set first; the rest are copies.
  std::sort(triples.begin(), triples.end());
  int duplicates = 0;
  for (std::size_t i = 1; i < triples.size(); ++i) {
    if (triples[i][0] == triples[i - 1][0] && triples[i][1] == triples[i - 1][1]) ++duplicates;
  }
  return duplicates;
}

VertexCounts vertex_counts(FacesRef F, const detail::VertexFaces& inc, std::int64_t v, Scratch& s) {
  VertexCounts counts;
  detail::collect_edge_sides(F, inc, v, s.sides);
  detail::for_each_edge(
      s.sides, [&](int other, const detail::EdgeSide* first, const detail::EdgeSide* last) {
        if (other < v) return;
        ++counts.edges;
        counts.boundary_edges += last - first == 1 ? 1 : 0;
        counts.non_manifold_edges += last - first >= 3 ? 1 : 0;
      });
  counts.non_manifold_vertex = fan_count(F, inc, v, s.sides, s.fan_parent) > 1;
  counts.duplicate_faces = duplicate_faces_at(F, inc, v, s.triples);
  return counts;
}

int degenerate_face_count(PositionsRef V, FacesRef F) {
  std::vector<std::uint8_t> degenerate(static_cast<std::size_t>(F.rows()));
  detail::parallel_for(F.rows(), 0, [&](std::int64_t f) {
    degenerate[static_cast<std::size_t>(f)] =
        detail::has_repeated_index(F, f) ||
        detail::is_degenerate_triangle(V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(),
                                       V.row(F(f, 2)).transpose());
  });
  return static_cast<int>(std::count(degenerate.begin(), degenerate.end(), 1));
}

}  // namespace

MeshStatistics mesh_statistics(PositionsRef V, FacesRef F) {
  validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), "mesh_statistics");
  MeshStatistics stats;
  stats.vertex_count = static_cast<int>(V.rows());
  stats.face_count = static_cast<int>(F.rows());
  if (V.rows() > 0) {
    stats.min_corner = V.colwise().minCoeff().transpose();
    stats.max_corner = V.colwise().maxCoeff().transpose();
  }
  stats.mean_edge_length = mean_edge_length(V, F);
  stats.degenerate_face_count = degenerate_face_count(V, F);
  stats.component_count = detail::face_components(V.rows(), F).count;

  const auto inc = detail::vertex_face_incidence(V.rows(), F);
  std::vector<VertexCounts> per_vertex(static_cast<std::size_t>(V.rows()));
  detail::PerThread<Scratch> scratch;
  detail::parallel_for(V.rows(), 0, [&](std::int64_t v) {
    per_vertex[static_cast<std::size_t>(v)] = vertex_counts(F, inc, v, scratch.local());
  });
  for (std::size_t v = 0; v < per_vertex.size(); ++v) {
    const auto& c = per_vertex[v];
    stats.edge_count += c.edges;
    stats.boundary_edge_count += c.boundary_edges;
    stats.non_manifold_edge_count += c.non_manifold_edges;
    stats.duplicate_face_count += c.duplicate_faces;
    stats.non_manifold_vertex_count += c.non_manifold_vertex ? 1 : 0;
    stats.unreferenced_vertex_count += inc.size(static_cast<std::int64_t>(v)) == 0 ? 1 : 0;
  }
  return stats;
}

}  // namespace focal
