#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/parallel.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/prepared.h"
#include "mesh/prepared_detail.h"
#include "mesh/statistics_detail.h"
#include "mesh/topology.h"

namespace focal {
namespace detail {
namespace {

// What one vertex contributes to the counts: edges to higher-indexed neighbours (so each edge is
// counted once), duplicate faces whose smallest index it is (so each face is examined once).
struct VertexCounts {
  int edges = 0;
  int boundary_edges = 0;
  int non_manifold_edges = 0;
  int duplicate_faces = 0;
  bool non_manifold_vertex = false;
  std::uint8_t edge_flags = 0;
  int neighbours = 0;  // distinct other ends of v's edges (written to `ring` when asked for)
};

struct Scratch {
  std::vector<EdgeSide> sides;
  std::vector<int> fan_parent;
  std::vector<std::uint64_t> pairs;  // (middle, largest index) of faces whose smallest is v
};

// Faces whose sorted index triple starts with v and repeats that of an earlier face. Only the
// number of repeats is needed, so the pairs are sorted without their faces.
int duplicate_faces_at(FacesRef F, const VertexFaces& inc, std::int64_t v,
                       std::vector<std::uint64_t>& pairs) {
  pairs.clear();
  for (int j = inc.begin(v); j < inc.end(v); ++j) {
    const int f = inc.faces[static_cast<std::size_t>(j)];
    std::array<int, 3> t{F(f, 0), F(f, 1), F(f, 2)};
    if (std::min({t[0], t[1], t[2]}) != v) continue;
    std::sort(t.begin(), t.end());
    pairs.push_back(static_cast<std::uint64_t>(t[1]) << 32 | static_cast<std::uint32_t>(t[2]));
  }
  sort_small(pairs.data(), pairs.data() + pairs.size(), std::less<>());
  int duplicates = 0;
  for (std::size_t i = 1; i < pairs.size(); ++i) duplicates += pairs[i] == pairs[i - 1] ? 1 : 0;
  return duplicates;
}

// All of v's findings from one sorted list of its edge sides. Fans: v's faces without a
// repeated index (direction != 0), joined whenever they share an edge at v; their number is the
// faces less the joins that merged two fans.
// With `ring`, also writes the other ends of v's edges there, ascending (its 1-ring: the same
// list as vertex_adjacency_from's).
VertexCounts vertex_counts(FacesRef F, const VertexFaces& inc, std::int64_t v, bool statistics,
                           Scratch& s, int* ring) {
  VertexCounts counts;
  const int proper_faces = collect_edge_sides(F, inc, v, s.sides);
  s.fan_parent.resize(statistics ? static_cast<std::size_t>(inc.size(v)) : 0);
  for (std::size_t i = 0; i < s.fan_parent.size(); ++i) s.fan_parent[i] = static_cast<int>(i);
  int joins = 0;
  for_each_edge(s.sides, [&](int other, const EdgeSide* first, const EdgeSide* last) {
    if (ring) ring[counts.neighbours] = other;
    ++counts.neighbours;
    const EdgeSide* anchor = nullptr;
    for (const auto* side = first; statistics && side < last; ++side) {
      if (side->direction == 0) continue;
      if (anchor) {
        const int a = find_root(s.fan_parent, anchor->local_face);
        const int b = find_root(s.fan_parent, side->local_face);
        joins += a != b ? 1 : 0;
        unite(s.fan_parent, a, b);
      } else {
        anchor = side;
      }
    }
    if (other < v) return;
    const auto faces = last - first;
    ++counts.edges;
    counts.boundary_edges += faces == 1 ? 1 : 0;
    counts.non_manifold_edges += faces >= 3 ? 1 : 0;
    if (faces != 2) {
      counts.edge_flags |= kOpenEdge;
    } else if (!is_consistent_interior_edge(first, last)) {
      counts.edge_flags |= kInconsistentEdge;
    }
  });
  if (!statistics) return counts;
  counts.non_manifold_vertex = proper_faces - joins > 1;
  counts.duplicate_faces = duplicate_faces_at(F, inc, v, s.pairs);
  return counts;
}

}  // namespace

MeshTopology mesh_topology(const VertexFaces& inc, FacesRef F, TopologyDetail detail, int threads,
                           Neighbourhoods* one_ring) {
  const bool statistics = detail == TopologyDetail::statistics;
  const std::int64_t vertex_count = inc.vertex_count();
  // The 1-ring as in vertex_adjacency_from: vertex v's list first goes to the slot at
  // 2 * inc.begin(v) of its own index array (each incident face adds at most two), then the
  // lists are moved down in place and the array shrunk: no second array of the 1-ring's size.
  // Each list's length goes to offsets[v + 1] first, summed into offsets afterwards.
  int* ring_buffer = nullptr;
  if (one_ring) {
    one_ring->indices.resize(static_cast<Eigen::Index>(2 * inc.faces.size()));
    one_ring->offsets.resize(vertex_count + 1);
    ring_buffer = one_ring->indices.data();
  }
  MeshTopology t;
  t.components = face_components(vertex_count, F, threads);
  t.edge_flags.resize(static_cast<std::size_t>(vertex_count));
  // Per-block sums of integers: exact, so the totals do not depend on the split.
  constexpr std::int64_t kBlock = 4096;
  const std::int64_t blocks = (vertex_count + kBlock - 1) / kBlock;
  std::vector<std::array<std::int64_t, 6>> sums(static_cast<std::size_t>(blocks));
  PerThread<Scratch> scratch(threads);
  parallel_blocks(
      vertex_count, kBlock, threads, [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
        Scratch& s = scratch.local();
        std::array<std::int64_t, 6> sum{};
        for (auto v = begin; v < end; ++v) {
          int* const ring =
              one_ring ? ring_buffer + 2 * static_cast<std::size_t>(inc.begin(v)) : nullptr;
          const VertexCounts c = vertex_counts(F, inc, v, statistics, s, ring);
          if (one_ring) one_ring->offsets[v + 1] = c.neighbours;
          t.edge_flags[static_cast<std::size_t>(v)] = c.edge_flags;
          sum[0] += c.edges;
          sum[1] += c.boundary_edges;
          sum[2] += c.non_manifold_edges;
          sum[3] += c.non_manifold_vertex ? 1 : 0;
          sum[4] += c.duplicate_faces;
          sum[5] += inc.size(v) == 0 ? 1 : 0;
        }
        sums[static_cast<std::size_t>(b)] = sum;
      });
  for (const auto& sum : sums) {
    t.edge_count += sum[0];
    t.boundary_edge_count += sum[1];
    t.non_manifold_edge_count += sum[2];
    t.non_manifold_vertex_count += sum[3];
    t.duplicate_face_count += sum[4];
    t.unreferenced_vertex_count += sum[5];
  }
  if (one_ring) {
    Neighbourhoods& ring = *one_ring;
    int total = 0;  // at most 2 * inc.faces.size() entries, whose offsets fit an int already
    ring.offsets[0] = 0;
    for (std::int64_t v = 0; v < vertex_count; ++v) {
      const int count = ring.offsets[v + 1];
      // Serial and in increasing v: each list moves down (total <= 2 * inc.begin(v)), never onto
      // a list not yet moved.
      // (An empty list is skipped: with no faces the buffer may be null, which memmove forbids.)
      if (count > 0) {
        std::memmove(ring_buffer + total, ring_buffer + 2 * static_cast<std::size_t>(inc.begin(v)),
                     static_cast<std::size_t>(count) * sizeof(int));
      }
      total += count;
      ring.offsets[v + 1] = total;
    }
    ring.indices.conservativeResize(total);
  }
  return t;
}

int degenerate_face_count(PositionsRef V, FacesRef F, int threads) {
  constexpr std::int64_t kBlock = 1 << 14;
  const std::int64_t blocks = (F.rows() + kBlock - 1) / kBlock;
  std::vector<int> count(static_cast<std::size_t>(blocks), 0);
  parallel_blocks(
      F.rows(), kBlock, threads, [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
        int n = 0;
        for (auto f = begin; f < end; ++f) {
          n += has_repeated_index(F, f) ||
               is_degenerate_triangle(V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(),
                                      V.row(F(f, 2)).transpose());
        }
        count[static_cast<std::size_t>(b)] = n;
      });
  int total = 0;
  for (const int n : count) total += n;
  return total;
}

}  // namespace detail

MeshStatistics mesh_statistics(PositionsRef V, FacesRef F, int threads) {
  const PreparedMesh mesh =
      detail::PreparedAccess::make(V, F, std::nullopt, {.threads = threads}, "mesh_statistics");
  MeshStatistics stats;
  stats.vertex_count = static_cast<int>(V.rows());
  stats.face_count = static_cast<int>(F.rows());
  if (V.rows() > 0) {
    stats.min_corner = V.colwise().minCoeff().transpose();
    stats.max_corner = V.colwise().maxCoeff().transpose();
  }
  stats.mean_edge_length = mesh.mean_edge_length();
  stats.degenerate_face_count = detail::degenerate_face_count(V, F, threads);
  const detail::MeshTopology t = detail::mesh_topology(*detail::incidence(mesh), F,
                                                       detail::TopologyDetail::statistics, threads);
  stats.component_count = t.components.count;
  stats.edge_count = static_cast<int>(t.edge_count);
  stats.boundary_edge_count = static_cast<int>(t.boundary_edge_count);
  stats.non_manifold_edge_count = static_cast<int>(t.non_manifold_edge_count);
  stats.non_manifold_vertex_count = static_cast<int>(t.non_manifold_vertex_count);
  stats.duplicate_face_count = static_cast<int>(t.duplicate_face_count);
  stats.unreferenced_vertex_count = static_cast<int>(t.unreferenced_vertex_count);
  return stats;
}

}  // namespace focal
