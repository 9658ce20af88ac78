#include "focal/mesh/neighbourhood.h"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "mesh/neighbourhood_detail.h"
#include "mesh/topology.h"

namespace focal {
namespace {

// Throws InvalidInput unless `n` is a well-formed CSR over its own vertices, so that the loops
// below can index without checks.
void check_csr(const Neighbourhoods& n, const char* what) {
  const std::string prefix = std::string(what) + ": neighbourhoods ";
  if (n.offsets.size() < 1 || n.offsets[0] != 0) {
    throw InvalidInput(prefix + "need #V + 1 offsets starting at 0");
  }
  const int vertices = n.vertex_count();
  for (int v = 0; v < vertices; ++v) {
    if (n.offsets[v + 1] < n.offsets[v]) {
      throw InvalidInput(prefix + "offsets decrease at vertex " + std::to_string(v));
    }
  }
  if (n.offsets[vertices] != n.indices.size()) {
    throw InvalidInput(prefix + "end at offset " + std::to_string(n.offsets[vertices]) +
                       " but have " + std::to_string(n.indices.size()) + " indices");
  }
  for (Eigen::Index i = 0; i < n.indices.size(); ++i) {
    if (n.indices[i] < 0 || n.indices[i] >= vertices) {
      throw InvalidInput(prefix + "entry " + std::to_string(i) + " is vertex " +
                         std::to_string(n.indices[i]) + ", but there are " +
                         std::to_string(vertices) + " vertices");
    }
  }
}

// Exclusive prefix sum of per-vertex counts into CSR offsets.
Eigen::VectorXi offsets_from_counts(const std::vector<int>& counts, const char* what) {
  Eigen::VectorXi offsets(static_cast<Eigen::Index>(counts.size()) + 1);
  std::int64_t total = 0;
  offsets[0] = 0;
  for (std::size_t v = 0; v < counts.size(); ++v) {
    total += counts[v];
    if (total > detail::kMaxCsrEntries) {
      throw InvalidInput(std::string(what) + ": more than 2^31 - 1 neighbour entries");
    }
    offsets[static_cast<Eigen::Index>(v) + 1] = static_cast<int>(total);
  }
  return offsets;
}

}  // namespace

Neighbourhoods vertex_adjacency(int vertex_count, FacesRef F) {
  // The parallel test first; the serial one only to name the first bad face.
  if (vertex_count < 0 || !detail::face_indices_in_range(vertex_count, F, 0)) {
    detail::check_face_indices(vertex_count, F, "vertex_adjacency");
  }
  return detail::vertex_adjacency_from(detail::vertex_face_incidence(vertex_count, F, 0), F, 0);
}

Neighbourhoods detail::vertex_adjacency_from(const VertexFaces& inc, FacesRef F, int threads) {
  const auto vertex_count = static_cast<int>(inc.vertex_count());
  // Each incident face adds at most two neighbours, so vertex v owns the slot starting at
  // 2 * inc.begin(v) of a scratch buffer: one pass fills it, a second compacts it.
  // Uninitialised: every slot is written before it is read, so no serial pass zeroes it
  // first.
  const auto buffer = std::make_unique_for_overwrite<int[]>(2 * inc.faces.size());
  std::vector<int> counts(static_cast<std::size_t>(vertex_count));
  detail::parallel_for(vertex_count, threads, [&](std::int64_t v) {
    int* const first = buffer.get() + 2 * static_cast<std::size_t>(inc.begin(v));
    int* last = first;
    for (int j = inc.begin(v); j < inc.end(v); ++j) {
      const int f = inc.faces[static_cast<std::size_t>(j)];
      for (int c = 0; c < 3; ++c) {
        if (F(f, c) != v) *last++ = F(f, c);
      }
    }
    detail::sort_small(first, last, std::less<>());  // a dozen entries: insertion sort
    counts[static_cast<std::size_t>(v)] = static_cast<int>(std::unique(first, last) - first);
  });
  Neighbourhoods result;
  result.offsets = offsets_from_counts(counts, "vertex_adjacency");
  result.indices.resize(result.offsets[vertex_count]);
  detail::parallel_for(vertex_count, threads, [&](std::int64_t v) {
    const int* first = buffer.get() + 2 * static_cast<std::size_t>(inc.begin(v));
    std::copy(first, first + counts[static_cast<std::size_t>(v)],
              result.indices.data() + result.offsets[v]);
  });
  return result;
}

namespace {

// Per-thread breadth-first-search state. `mark[w] == v + 1` means w was reached from source v:
// every source is searched once per call, so the marks never need clearing.
struct BfsScratch {
  std::vector<int> mark;   // #V
  std::vector<int> queue;  // #V + 1: the source, then its rings in search order

  // Allocates on a thread's first block only.
  void prepare(int vertex_count) {
    if (mark.empty()) mark.assign(static_cast<std::size_t>(vertex_count), 0);
    if (queue.empty()) queue.resize(static_cast<std::size_t>(vertex_count) + 1);
  }
};

// Appends the k-ring of v to `out`, ring by ring, each ring sorted; returns its size, or -1
// (appending nothing) as soon as it holds more than kMaxNeighbourhoodSize vertices: the search
// stops there, so a vertex next to a hub of 100k neighbours costs O(cap), not O(100k).
int append_k_ring(const Neighbourhoods& one_ring, int k, int v, BfsScratch& s,
                  std::vector<int>& out) {
  // Raw pointers: through the containers the compiler would reload every base pointer per
  // neighbour, for fear that a store aliases it.
  const int* const offsets = one_ring.offsets.data();
  const int* const indices = one_ring.indices.data();
  int* const mark = s.mark.data();
  int* const queue = s.queue.data();
  const int stamp = v + 1;
  mark[v] = stamp;
  queue[0] = v;
  int ring_begin = 0;
  int size = 1;
  for (int depth = 1; depth <= k && ring_begin < size; ++depth) {
    const int ring_end = size;
    for (int q = ring_begin; q < ring_end; ++q) {
      for (int e = offsets[queue[q]]; e < offsets[queue[q] + 1]; ++e) {
        const int w = indices[e];
        if (mark[w] != stamp) {
          if (size > kMaxNeighbourhoodSize) return -1;  // v itself is queue[0]
          mark[w] = stamp;
          queue[size++] = w;
        }
      }
    }
    std::sort(queue + ring_end, queue + size);
    ring_begin = ring_end;
  }
  out.insert(out.end(), queue + 1, queue + size);
  return size - 1;
}

// Vertices are searched in this many contiguous blocks, each appending to its own vector, and the
// blocks are concatenated in order: one search per vertex (a count pass and a fill pass would
// search twice) and a deterministic result. More blocks than parallel_for's serial cutoff (1024)
// keep large meshes parallel and balanced.
constexpr int kRingBlocks = 2048;

}  // namespace

Neighbourhoods k_ring(const Neighbourhoods& one_ring, int k) {
  if (k < 1) throw InvalidInput("k_ring: k must be at least 1, got " + std::to_string(k));
  check_csr(one_ring, "k_ring");
  if (k == 1) return one_ring;
  const int n = one_ring.vertex_count();
  const int blocks = std::min(n, kRingBlocks);
  const auto block_begin = [&](std::int64_t b) {
    return static_cast<int>(b * static_cast<std::int64_t>(n) / blocks);
  };
  std::vector<std::vector<int>> block_rings(static_cast<std::size_t>(blocks));
  std::vector<int> counts(static_cast<std::size_t>(n));
  detail::PerThread<BfsScratch> scratch(0);
  detail::parallel_for(blocks, 0, [&](std::int64_t b) {
    BfsScratch& s = scratch.local();
    s.prepare(n);
    auto& out = block_rings[static_cast<std::size_t>(b)];
    for (int v = block_begin(b); v < block_begin(b + 1); ++v) {
      counts[static_cast<std::size_t>(v)] = std::max(append_k_ring(one_ring, k, v, s, out), 0);
    }
  });
  Neighbourhoods result;
  result.offsets = offsets_from_counts(counts, "k_ring");
  result.indices.resize(result.offsets[n]);
  detail::parallel_for(blocks, 0, [&](std::int64_t b) {
    auto& ring = block_rings[static_cast<std::size_t>(b)];
    std::copy(ring.begin(), ring.end(), result.indices.data() + result.offsets[block_begin(b)]);
    std::vector<int>().swap(ring);  // frees memory early: the result is as large again
  });
  return result;
}

std::vector<int> crowded_vertices(const Neighbourhoods& one_ring, int k) {
  if (k < 1) throw InvalidInput("crowded_vertices: k must be at least 1, got " + std::to_string(k));
  check_csr(one_ring, "crowded_vertices");
  const int n = one_ring.vertex_count();
  if (k == 1) return {};
  std::vector<std::uint8_t> crowded(static_cast<std::size_t>(n), 0);
  detail::PerThread<BfsScratch> scratch(0);
  detail::PerThread<std::vector<int>> rings(0);
  detail::parallel_for(n, 0, [&](std::int64_t v) {
    BfsScratch& s = scratch.local();
    s.prepare(n);
    std::vector<int>& ring = rings.local();
    ring.clear();
    crowded[static_cast<std::size_t>(v)] =
        append_k_ring(one_ring, k, static_cast<int>(v), s, ring) < 0 ? 1 : 0;
  });
  std::vector<int> result;
  for (int v = 0; v < n; ++v) {
    if (crowded[static_cast<std::size_t>(v)] != 0) result.push_back(v);
  }
  return result;
}

std::vector<bool> boundary_vertices(int vertex_count, FacesRef F) {
  detail::check_face_indices(vertex_count, F, "boundary_vertices");
  const auto inc = detail::vertex_face_incidence(vertex_count, F, 0);
  // Bytes, not std::vector<bool>: neighbouring bits of a vector<bool> share a word, so writing
  // them from different threads would race.
  std::vector<std::uint8_t> flags(static_cast<std::size_t>(vertex_count), 0);
  detail::PerThread<std::vector<detail::EdgeSide>> scratch(0);
  detail::parallel_for(vertex_count, 0, [&](std::int64_t v) {
    auto& sides = scratch.local();
    detail::collect_edge_sides(F, inc, v, sides);
    bool boundary = false;
    detail::for_each_edge(sides,
                          [&](int, const detail::EdgeSide* first, const detail::EdgeSide* last) {
                            boundary = boundary || last - first == 1;
                          });
    flags[static_cast<std::size_t>(v)] = boundary ? 1 : 0;
  });
  return {flags.begin(), flags.end()};
}

Eigen::VectorXi rings_to_boundary(const Neighbourhoods& one_ring, const std::vector<bool>& boundary,
                                  int max_rings) {
  check_csr(one_ring, "rings_to_boundary");
  const int n = one_ring.vertex_count();
  if (boundary.size() != static_cast<std::size_t>(n)) {
    throw InvalidInput("rings_to_boundary: " + std::to_string(boundary.size()) +
                       " boundary flags for " + std::to_string(n) + " vertices");
  }
  if (max_rings < 0 || max_rings == std::numeric_limits<int>::max()) {
    throw InvalidInput("rings_to_boundary: max_rings must be in [0, INT_MAX), got " +
                       std::to_string(max_rings));
  }
  // Multi-source breadth-first search: serial, but linear in the edges and stopped at max_rings.
  Eigen::VectorXi rings = Eigen::VectorXi::Constant(n, max_rings + 1);
  std::vector<int> queue;
  for (int v = 0; v < n; ++v) {
    if (boundary[static_cast<std::size_t>(v)]) {
      rings[v] = 0;
      queue.push_back(v);
    }
  }
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const int u = queue[q];
    if (rings[u] == max_rings) continue;
    for (const int* w = one_ring.begin(u); w != one_ring.end(u); ++w) {
      if (rings[*w] > rings[u] + 1) {
        rings[*w] = rings[u] + 1;
        queue.push_back(*w);
      }
    }
  }
  return rings;
}

}  // namespace focal
