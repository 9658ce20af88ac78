#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/parallel.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/prepared.h"
#include "mesh/prepared_access.h"
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

// The largest valence regular_vertex_counts takes (a face position fits 4 bits of its keys);
// higher ones, rare, take the general path.
constexpr int kMaxRegularValence = 16;

// The common vertex, without the edge sides: k >= 3 faces, none with a repeated index, that
// form one closed fan. Each face at v has a successor `next` (edge v -> next) and a predecessor
// `prev` (edge prev -> v). When the sorted nexts are strictly increasing and equal the sorted
// prevs, every edge at v has exactly two faces (the one it is next of, the one it is prev of),
// traversed in opposite directions, and pairing the two in sorted order is a permutation
// sigma of the faces (face to the face across its next edge); one cycle of sigma is one fan. No
// two such faces share their corners (that takes (v, a, b) and (v, b, a): a cycle of 2 < k).
// The counts are then those the general path finds: k edges, none open or inconsistent, no
// duplicate face, a manifold vertex, and the sorted nexts are the 1-ring. Returns false, with
// nothing written, for any other vertex.
bool regular_vertex_counts(FacesRef F, const VertexFaces& inc, std::int64_t v, VertexCounts& counts,
                           int* ring) {
  const int k = inc.size(v);
  if (k < 3 || k > kMaxRegularValence) return false;
  // (other end << 4 | face position): one 64-bit key sorts by the other end, and keeps the face.
  std::array<std::uint64_t, kMaxRegularValence> next, prev;
  const int* const faces = inc.faces.data() + inc.begin(v);
  for (int i = 0; i < k; ++i) {
    const int a = F(faces[i], 0), b = F(faces[i], 1), c = F(faces[i], 2);
    if (a == b || b == c || a == c) return false;
    const auto face = static_cast<std::uint64_t>(i);
    next[static_cast<std::size_t>(i)] =
        static_cast<std::uint64_t>(a == v ? b : (b == v ? c : a)) << 4 | face;
    prev[static_cast<std::size_t>(i)] =
        static_cast<std::uint64_t>(a == v ? c : (b == v ? a : b)) << 4 | face;
  }
  sort_small(next.data(), next.data() + k, std::less<>());
  sort_small(prev.data(), prev.data() + k, std::less<>());
  std::array<std::uint8_t, kMaxRegularValence> sigma;
  for (std::size_t r = 0; r < static_cast<std::size_t>(k); ++r) {
    const std::uint64_t other = next[r] >> 4;
    if (other != prev[r] >> 4 || (r > 0 && other == next[r - 1] >> 4)) return false;
    sigma[next[r] & 15] = static_cast<std::uint8_t>(prev[r] & 15);
  }
  std::uint8_t face = 0;
  for (int step = 1; step < k; ++step) {
    face = sigma[face];
    if (face == 0) return false;  // a cycle shorter than k: more than one fan
  }
  counts.neighbours = k;
  for (std::size_t r = 0; r < static_cast<std::size_t>(k); ++r) {
    const auto other = static_cast<int>(next[r] >> 4);
    counts.edges += other > v ? 1 : 0;
    if (ring) ring[r] = other;
  }
  return true;
}

// All of v's findings from one sorted list of its edge sides. Fans: v's faces without a
// repeated index (direction != 0), joined whenever they share an edge at v; their number is the
// faces less the joins that merged two fans.
// With `ring`, also writes the other ends of v's edges there, ascending (its 1-ring: the same
// list as vertex_adjacency_from's).
VertexCounts vertex_counts(FacesRef F, const VertexFaces& inc, std::int64_t v, bool statistics,
                           Scratch& s, int* ring) {
  VertexCounts counts;
  if (regular_vertex_counts(F, inc, v, counts, ring)) return counts;
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
  // The 1-ring as in vertex_adjacency_from, in its own index array of 2 #faces-at-v entries
  // (each incident face adds at most two neighbours): each block of vertices writes its lists one
  // after the other from where its share of that array begins (vertex v's list never reaches
  // 2 * inc.end(v), so blocks never meet), then the blocks' runs are moved down in order and the
  // array shrunk: no second array of the 1-ring's size, and a few hundred moves, not one per
  // vertex. offsets[v + 1] first holds where v's list ends within its block's run.
  int* ring_buffer = nullptr;
  if (one_ring) {
    one_ring->indices.resize(static_cast<Eigen::Index>(2 * inc.faces.size()));
    one_ring->offsets.resize(vertex_count + 1);
    ring_buffer = one_ring->indices.data();
  }
  const auto block_ring = [&](std::int64_t begin) {
    return ring_buffer + 2 * static_cast<std::size_t>(inc.begin(begin));
  };
  MeshTopology t;
  t.components = face_components(vertex_count, F, threads);
  t.edge_flags.resize(static_cast<std::size_t>(vertex_count));
  // Per-block sums of integers: exact, so the totals do not depend on the split.
  constexpr std::int64_t kBlock = 4096;
  const std::int64_t blocks = (vertex_count + kBlock - 1) / kBlock;
  std::vector<std::array<std::int64_t, 7>> sums(static_cast<std::size_t>(blocks));
  PerThread<Scratch> scratch(threads);
  parallel_blocks(vertex_count, kBlock, threads,
                  [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
                    Scratch& s = scratch.local();
                    std::array<std::int64_t, 7> sum{};
                    int ring_size = 0;  // of this block's run so far
                    for (auto v = begin; v < end; ++v) {
                      int* const ring = one_ring ? block_ring(begin) + ring_size : nullptr;
                      const VertexCounts c = vertex_counts(F, inc, v, statistics, s, ring);
                      ring_size += c.neighbours;
                      if (one_ring) one_ring->offsets[v + 1] = ring_size;
                      t.edge_flags[static_cast<std::size_t>(v)] = c.edge_flags;
                      sum[0] += c.edges;
                      sum[1] += c.boundary_edges;
                      sum[2] += c.non_manifold_edges;
                      sum[3] += c.non_manifold_vertex ? 1 : 0;
                      sum[4] += c.duplicate_faces;
                      sum[5] += inc.size(v) == 0 ? 1 : 0;
                    }
                    sum[6] = ring_size;
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
    // Where each block's run goes: at most 2 * inc.faces.size() entries, whose offsets fit an int
    // already.
    std::vector<int> run_begin(static_cast<std::size_t>(blocks));
    int total = 0;
    for (std::int64_t b = 0; b < blocks; ++b) {
      run_begin[static_cast<std::size_t>(b)] = total;
      const auto size = static_cast<int>(sums[static_cast<std::size_t>(b)][6]);
      // Serial and in block order: each run moves down (total <= 2 * inc.begin(its first
      // vertex)), never onto a run not yet moved. (An empty run is skipped: with no faces the
      // buffer may be null, which memmove forbids.)
      if (size > 0) {
        std::memmove(ring_buffer + total, block_ring(b * kBlock),
                     static_cast<std::size_t>(size) * sizeof(int));
      }
      total += size;
    }
    ring.offsets[0] = 0;
    parallel_blocks(vertex_count, kBlock, threads,
                    [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
                      const int base = run_begin[static_cast<std::size_t>(b)];
                      for (auto v = begin; v < end; ++v) ring.offsets[v + 1] += base;
                    });
    ring.indices.conservativeResize(total);
  }
  return t;
}

DegenerateFaces degenerate_faces(PositionsRef V, FacesRef F, int threads) {
  constexpr std::int64_t kBlock = 1 << 14;
  const std::int64_t blocks = (F.rows() + kBlock - 1) / kBlock;
  std::vector<DegenerateFaces> count(static_cast<std::size_t>(blocks));
  parallel_blocks(
      F.rows(), kBlock, threads, [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
        DegenerateFaces n;
        for (auto f = begin; f < end; ++f) {
          if (has_repeated_index(F, f)) {
            ++n.repeated_index;
          } else {
            n.zero_area += is_degenerate_triangle(
                V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(), V.row(F(f, 2)).transpose());
          }
        }
        count[static_cast<std::size_t>(b)] = n;
      });
  DegenerateFaces total;
  for (const DegenerateFaces& n : count) {
    total.repeated_index += n.repeated_index;
    total.zero_area += n.zero_area;
  }
  return total;
}

}  // namespace detail

MeshStatistics mesh_statistics(PositionsRef V, FacesRef F) {
  const PreparedMesh mesh = detail::PreparedAccess::make(V, F, std::nullopt, {}, "mesh_statistics");
  MeshStatistics stats;
  stats.vertex_count = static_cast<int>(V.rows());
  stats.face_count = static_cast<int>(F.rows());
  if (V.rows() > 0) {
    stats.min_corner = V.colwise().minCoeff().transpose();
    stats.max_corner = V.colwise().maxCoeff().transpose();
  }
  stats.mean_edge_length = mesh.mean_edge_length();
  const detail::DegenerateFaces degenerate = detail::degenerate_faces(V, F, 0);
  stats.degenerate_face_count = static_cast<int>(degenerate.repeated_index + degenerate.zero_area);
  const detail::MeshTopology t =
      detail::mesh_topology(*detail::incidence(mesh), F, detail::TopologyDetail::statistics, 0);
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
