#pragma once
// Internal, header-only: the vertex->face incidence that normals/vertex_normals.cpp,
// neighbourhood.cpp and statistics.cpp gather over. Every per-vertex loop built on it reads the
// faces of its own vertex in ascending face order and writes only that vertex's slot, so results
// are identical for any thread count (no scatter-adds, no atomics, no hash maps per edge).
//
// Edge conventions shared by those files: an edge {a, b} is a pair of distinct vertices that are
// corners of a common face; its incident faces are the faces having both as corners (each face
// once, also one with a repeated index such as (a, a, b)). A face traverses the edge a -> b when b
// follows a counter-clockwise; a face with a repeated index traverses it both ways, i.e. has no
// direction along it.

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/core/mesh.h"

namespace focal::detail {

/// Calls body(b, begin, end) for the blocks [begin, end) = [b block, min(n, (b + 1) block)) of
/// [0, n), in parallel on `threads` threads (see thread_count). For loops that keep a result per
/// block: parallel_for(blocks, ...) sees only the block count, and its serial cutoff (1024
/// iterations) had every such loop run on one thread for meshes below 4M vertices.
template <class Body>
void parallel_blocks(std::int64_t n, std::int64_t block, int threads, Body&& body) {
  parallel_for_blocks(n, block, threads, [&](std::int64_t begin, std::int64_t end) {
    body(begin / block, begin, end);
  });
}

/// Per-key totals over [0, n) in parallel: totals[key(i)] += item i (add(total, i)), for the
/// i with key(i) >= 0. Each block of 16384 items adds up its runs of equal keys from a zero
/// Total, and the runs are added to `totals` in block order: the same result for any thread
/// count, exact for integers. For per-component sums, since a mesh's vertices and faces mostly
/// come in runs by component; a per-thread array per key would cost #threads x #keys.
template <class Total, class Key, class Add>
void add_by_key_runs(std::int64_t n, int threads, Key&& key, Add&& add,
                     std::vector<Total>& totals) {
  constexpr std::int64_t kBlock = 1 << 14;
  std::vector<std::vector<std::pair<int, Total>>> runs(
      static_cast<std::size_t>((n + kBlock - 1) / kBlock));
  parallel_blocks(n, kBlock, threads, [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
    auto& block_runs = runs[static_cast<std::size_t>(b)];
    for (auto i = begin; i < end; ++i) {
      const int k = key(i);
      if (k < 0) continue;
      if (block_runs.empty() || block_runs.back().first != k) block_runs.emplace_back(k, Total{});
      add(block_runs.back().second, i);
    }
  });
  for (const auto& block_runs : runs) {
    for (const auto& [k, run] : block_runs) totals[static_cast<std::size_t>(k)] += run;
  }
}

/// Largest number of entries a CSR array with 32-bit offsets (Eigen::VectorXi) can hold.
inline constexpr std::int64_t kMaxCsrEntries = std::numeric_limits<int>::max();

/// Throws InvalidInput unless vertex_count >= 0 and every index of F lies in [0, vertex_count).
/// For callers that have a vertex count but no positions (validate_mesh_arrays needs V).
inline void check_face_indices(std::int64_t vertex_count, FacesRef F, const char* what) {
  if (vertex_count < 0) {
    throw InvalidInput(std::string(what) + ": vertex count " + std::to_string(vertex_count) +
                       " is negative");
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const std::int64_t idx = F(f, c);
      if (idx < 0 || idx >= vertex_count) {
        throw InvalidInput(std::string(what) + ": face " + std::to_string(f) +
                           " refers to vertex " + std::to_string(idx) + ", but there are " +
                           std::to_string(vertex_count) + " vertices");
      }
    }
  }
}

/// True when face f has a repeated vertex index (it spans no triangle).
inline bool has_repeated_index(FacesRef F, Eigen::Index f) {
  return F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 0) == F(f, 2);
}

/// Relative area threshold: a triangle is degenerate when |cross| <= kDegenerateArea * L^2 with L
/// its longest edge. |cross| / L^2 is scale invariant (about twice the sine of the smallest angle
/// for thin triangles), and 1e-14 sits a few dozen ulps above what rounding leaves of an exactly
/// flat triangle, so only numerically collinear corners are caught, at any scale.
inline constexpr double kDegenerateArea = 1e-14;

/// Whether the triangle (a, b, c) has numerically zero area (see kDegenerateArea).
inline bool is_degenerate_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Eigen::Vector3d& c) {
  const double longest_sq =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return (b - a).cross(c - a).norm() <= kDegenerateArea * longest_sq;
}

/// An allocator whose value-less construct() leaves a new element uninitialised, so that
/// resize() does not zero the array: for arrays of ints that a parallel pass then writes in full.
/// Zeroing them first wrote every page on one thread (its page faults included) before the
/// parallel pass wrote it again.
template <class T>
struct DefaultInitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <class U>
  explicit DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

/// A std::vector whose resize() leaves new ints uninitialised (DefaultInitAllocator).
template <class T>
using UninitVector = std::vector<T, DefaultInitAllocator<T>>;

/// Faces containing each vertex in CSR form: `faces[offsets[v] .. offsets[v+1])`, ascending, each
/// face once even when it repeats the vertex.
struct VertexFaces {
  UninitVector<int> offsets;  ///< #V + 1
  UninitVector<int> faces;

  [[nodiscard]] int begin(std::int64_t v) const { return offsets[static_cast<std::size_t>(v)]; }
  [[nodiscard]] int end(std::int64_t v) const { return offsets[static_cast<std::size_t>(v) + 1]; }
  [[nodiscard]] int size(std::int64_t v) const { return end(v) - begin(v); }
  [[nodiscard]] std::int64_t vertex_count() const {
    return static_cast<std::int64_t>(offsets.size()) - 1;
  }
};

/// Face chunks of the parallel counting sort below: each chunk counts into an #V array of its
/// own, so more chunks cost memory (4 #V bytes each) and a longer prefix pass.
inline int incidence_chunks(std::int64_t face_count, int threads) {
  constexpr std::int64_t kMinFacesPerChunk = 1 << 16;
  const std::int64_t by_size = std::max<std::int64_t>(1, face_count / kMinFacesPerChunk);
  return static_cast<int>(std::min<std::int64_t>({by_size, thread_count(threads), 8}));
}

/// Visits the distinct corners of face f, so that (a, a, b) is listed once under a.
template <class Fn>
void for_each_distinct_corner(FacesRef F, Eigen::Index f, Fn&& fn) {
  const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
  fn(a);
  if (b != a) fn(b);
  if (c != a && c != b) fn(c);
}

/// Builds the incidence by a counting sort over the faces. The faces are split into consecutive
/// chunks that count and fill in parallel; chunk k's faces go after those of chunks < k in each
/// list, so every list is ascending and the result is the same for any thread count.
/// F must already be validated against vertex_count.
/// \throw InvalidInput when 3 #F exceeds 32-bit offsets.
inline VertexFaces vertex_face_incidence(std::int64_t vertex_count, FacesRef F, int threads) {
  if (3 * static_cast<std::int64_t>(F.rows()) > kMaxCsrEntries) {
    throw InvalidInput("too many faces (" + std::to_string(F.rows()) +
                       ") for 32-bit neighbourhood offsets");
  }
  const auto n = static_cast<std::size_t>(vertex_count);
  const int chunks = incidence_chunks(F.rows(), threads);
  const auto chunk_begin = [&](std::int64_t k) { return k * F.rows() / chunks; };
  // cursor[k][v]: first counts of chunk k's faces at v, then where chunk k writes its next face.
  std::vector<std::vector<int>> cursor(static_cast<std::size_t>(chunks));
  parallel_chunks(chunks, threads, [&](std::int64_t k) {
    auto& count = cursor[static_cast<std::size_t>(k)];
    count.assign(n, 0);
    for (auto f = chunk_begin(k); f < chunk_begin(k + 1); ++f) {
      for_each_distinct_corner(F, f, [&](int v) { ++count[static_cast<std::size_t>(v)]; });
    }
  });
  VertexFaces inc;
  inc.offsets.resize(n + 1);
  int total = 0;
  for (std::size_t v = 0; v < n; ++v) {
    inc.offsets[v] = total;
    for (auto& c : cursor) total += std::exchange(c[v], total);
  }
  inc.offsets[n] = total;
  inc.faces.resize(static_cast<std::size_t>(total));
  parallel_chunks(chunks, threads, [&](std::int64_t k) {
    auto& next = cursor[static_cast<std::size_t>(k)];
    for (auto f = chunk_begin(k); f < chunk_begin(k + 1); ++f) {
      for_each_distinct_corner(F, f, [&](int v) {
        inc.faces[static_cast<std::size_t>(next[static_cast<std::size_t>(v)]++)] =
            static_cast<int>(f);
      });
    }
  });
  return inc;
}

/// One incident face of an edge seen from one endpoint v: the other endpoint, the face's position
/// in v's incidence list, and its direction (+1: v -> other, -1: other -> v, 0: both ways).
struct EdgeSide {
  int other;
  int local_face;
  int direction;
};

/// Sorts a short range by `less` in place: insertion sort for the dozen entries of a typical
/// vertex (std::sort's call and dispatch cost more than the sort there), std::sort beyond.
template <class T, class Less>
void sort_small(T* first, T* last, Less less) {
  if (last - first > 32) return std::sort(first, last, less);
  for (T* i = first + (first != last); i < last; ++i) {
    const T x = *i;
    T* j = i;
    for (; j > first && less(x, j[-1]); --j) *j = j[-1];
    *j = x;
  }
}

/// Fills `sides` with one entry per (edge at v, incident face), sorted by (other, local_face), so
/// that the faces of each edge at v are consecutive. Returns how many incident faces have no
/// repeated index (their sides have direction +1 or -1; the others' have 0).
inline int collect_edge_sides(FacesRef F, const VertexFaces& inc, std::int64_t v,
                              std::vector<EdgeSide>& sides) {
  const int begin = inc.begin(v), count = inc.size(v);
  // Every face has at most two sides at v; written through a pointer (no push_back checks).
  sides.resize(2 * static_cast<std::size_t>(count));
  EdgeSide* out = sides.data();
  int proper = 0;
  for (int local = 0; local < count; ++local) {
    const int f = inc.faces[static_cast<std::size_t>(begin + local)];
    const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
    if (a != b && b != c && a != c) {
      // v is exactly one corner: its successor is traversed v -> next, its predecessor prev -> v.
      const int next = a == v ? b : (b == v ? c : a);
      const int prev = a == v ? c : (b == v ? a : b);
      *out++ = {next, local, +1};
      *out++ = {prev, local, -1};
      ++proper;
      continue;
    }
    // A face with a repeated index lists its edge at v both ways: one side, direction 0.
    for (int k = 0; k < 3; ++k) {
      const int p = F(f, k), q = F(f, (k + 1) % 3);
      if (p != q && (p == v || q == v)) {
        *out++ = {p == v ? q : p, local, 0};
        break;
      }
    }
  }
  sides.resize(static_cast<std::size_t>(out - sides.data()));
  // One 64-bit comparison instead of two branches: both fields are non-negative ints.
  const auto key = [](const EdgeSide& x) {
    return static_cast<std::uint64_t>(x.other) << 32 | static_cast<std::uint32_t>(x.local_face);
  };
  sort_small(sides.data(), out,
             [&](const EdgeSide& x, const EdgeSide& y) { return key(x) < key(y); });
  return proper;
}

/// Calls fn(other, first, last) for each edge {v, other} in the sorted output of
/// collect_edge_sides; [first, last) are its incident faces.
template <class Fn>
void for_each_edge(const std::vector<EdgeSide>& sides, Fn&& fn) {
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i + 1;
    while (j < sides.size() && sides[j].other == sides[i].other) ++j;
    fn(sides[i].other, sides.data() + i, sides.data() + j);
    i = j;
  }
}

/// Whether an edge with incident faces [first, last) is interior (two faces) and traversed in
/// opposite directions by them.
inline bool is_consistent_interior_edge(const EdgeSide* first, const EdgeSide* last) {
  return last - first == 2 && first[0].direction != 0 && first[0].direction == -first[1].direction;
}

/// One scratch object per thread of detail::parallel_for(n, threads, ...) (or _blocks): a loop
/// on `threads` threads numbers them worker_slot() in [0, thread_count(threads)), so each
/// indexes a slot of its own.
template <class T>
class PerThread {
 public:
  explicit PerThread(int threads) : slots_(static_cast<std::size_t>(thread_count(threads))) {}
  T& local() { return slots_[static_cast<std::size_t>(worker_slot())]; }

 private:
  std::vector<T> slots_;
};

/// Union-find root with path halving.
inline int find_root(std::vector<int>& parent, int x) {
  while (parent[static_cast<std::size_t>(x)] != x) {
    parent[static_cast<std::size_t>(x)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    x = parent[static_cast<std::size_t>(x)];
  }
  return x;
}

/// Joins the sets of a and b, keeping the smaller root (any rule would do; this one is simple).
inline void unite(std::vector<int>& parent, int a, int b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  if (a < b) {
    parent[static_cast<std::size_t>(b)] = a;
  } else if (b < a) {
    parent[static_cast<std::size_t>(a)] = b;
  }
}

/// Connected components of faces, where faces sharing a vertex are connected.
struct FaceComponents {
  UninitVector<int> face_component;    ///< #F, numbered in order of each component's first face
  UninitVector<int> vertex_component;  ///< #V, -1 for vertices in no face
  int count = 0;
};

/// Root of x in a union-find forest shared by threads, whose links always point to a smaller
/// index (so a root is the smallest vertex of its set). Path halving writes only to non-roots and
/// only replaces a parent by one of its ancestors, so it cannot undo a concurrent link.
inline int find_shared_root(int* parent, int x) {
  for (;;) {
    std::atomic_ref<int> link(parent[x]);
    const int p = link.load(std::memory_order_relaxed);
    if (p == x) return x;
    const int grand = std::atomic_ref<int>(parent[p]).load(std::memory_order_relaxed);
    if (grand != p) link.store(grand, std::memory_order_relaxed);
    x = grand;
  }
}

/// Joins the sets of a and b in a forest shared by threads: the larger root is linked under the
/// smaller by compare-and-swap, retried when another thread linked it first.
inline void unite_shared(int* parent, int a, int b) {
  for (;;) {
    a = find_shared_root(parent, a);
    b = find_shared_root(parent, b);
    if (a == b) return;
    if (a < b) std::swap(a, b);
    int expected = a;
    if (std::atomic_ref<int>(parent[a]).compare_exchange_weak(expected, b,
                                                              std::memory_order_relaxed)) {
      return;
    }
  }
}

/// Numbers the sets of `root` (#V, each vertex's set root) in order of their first face:
/// label[r] for each root r of a face's corners, -1 elsewhere. Returns the number of sets.
inline int label_components_by_first_face(FacesRef F, const UninitVector<int>& root,
                                          std::vector<int>& label, int threads) {
  // first[r]: the smallest face of set r, by an atomic minimum (the same for any schedule).
  std::vector<int> first(root.size(), std::numeric_limits<int>::max());
  parallel_for(F.rows(), threads, [&](std::int64_t f) {
    std::atomic_ref<int> slot(
        first[static_cast<std::size_t>(root[static_cast<std::size_t>(F(f, 0))])]);
    int current = slot.load(std::memory_order_relaxed);
    while (f < current &&
           !slot.compare_exchange_weak(current, static_cast<int>(f), std::memory_order_relaxed)) {
    }
  });
  // Faces that start a set, counted per block and numbered in face order.
  constexpr std::int64_t kBlock = 1 << 14;
  const std::int64_t blocks = (F.rows() + kBlock - 1) / kBlock;
  const auto starts_set = [&](std::int64_t f) {
    return first[static_cast<std::size_t>(root[static_cast<std::size_t>(F(f, 0))])] == f;
  };
  std::vector<int> block_start(static_cast<std::size_t>(blocks) + 1, 0);
  parallel_blocks(F.rows(), kBlock, threads,
                  [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
                    int n = 0;
                    for (auto f = begin; f < end; ++f) n += starts_set(f);
                    block_start[static_cast<std::size_t>(b) + 1] = n;
                  });
  for (std::size_t b = 0; b < static_cast<std::size_t>(blocks); ++b) {
    block_start[b + 1] += block_start[b];
  }
  label.assign(root.size(), -1);
  parallel_blocks(
      F.rows(), kBlock, threads, [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
        int next = block_start[static_cast<std::size_t>(b)];
        for (auto f = begin; f < end; ++f) {
          if (starts_set(f))
            label[static_cast<std::size_t>(root[static_cast<std::size_t>(F(f, 0))])] = next++;
        }
      });
  return block_start.back();
}

/// Union-find over vertices, in parallel (shared forest, see unite_shared). The sets do not
/// depend on the order of the unions and each is numbered by its first face, so the result is
/// the same for any thread count. F must already be validated against vertex_count.
inline FaceComponents face_components(std::int64_t vertex_count, FacesRef F, int threads) {
  const auto n = static_cast<std::size_t>(vertex_count);
  UninitVector<int> parent(n);  // written in full by the parallel pass below
  parallel_for(vertex_count, threads,
               [&](std::int64_t v) { parent[static_cast<std::size_t>(v)] = static_cast<int>(v); });
  parallel_for(F.rows(), threads, [&](std::int64_t f) {
    unite_shared(parent.data(), F(f, 0), F(f, 1));
    unite_shared(parent.data(), F(f, 0), F(f, 2));
  });
  UninitVector<int> root(n);
  parallel_for(vertex_count, threads, [&](std::int64_t v) {
    root[static_cast<std::size_t>(v)] = find_shared_root(parent.data(), static_cast<int>(v));
  });
  FaceComponents result;
  std::vector<int> label;
  result.count = label_components_by_first_face(F, root, label, threads);
  result.face_component.resize(static_cast<std::size_t>(F.rows()));
  parallel_for(F.rows(), threads, [&](std::int64_t f) {
    result.face_component[static_cast<std::size_t>(f)] =
        label[static_cast<std::size_t>(root[static_cast<std::size_t>(F(f, 0))])];
  });
  // An unreferenced vertex is its own, never labelled root, hence -1.
  result.vertex_component.resize(n);
  parallel_for(vertex_count, threads, [&](std::int64_t v) {
    result.vertex_component[static_cast<std::size_t>(v)] =
        label[static_cast<std::size_t>(root[static_cast<std::size_t>(v)])];
  });
  return result;
}

/// True when every index of F lies in [0, vertex_count), checked in parallel; callers then call
/// validate_mesh_arrays only to produce its message for the first bad face.
inline bool face_indices_in_range(std::int64_t vertex_count, FacesRef F, int threads) {
  constexpr std::int64_t kBlock = 1 << 14;
  const std::int64_t blocks = (F.rows() + kBlock - 1) / kBlock;
  std::vector<std::uint8_t> bad(static_cast<std::size_t>(blocks), 0);
  parallel_blocks(F.rows(), kBlock, threads,
                  [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
                    bool any = false;
                    for (auto f = begin; f < end; ++f) {
                      for (int c = 0; c < 3; ++c) any |= F(f, c) < 0 || F(f, c) >= vertex_count;
                    }
                    bad[static_cast<std::size_t>(b)] = any;
                  });
  return std::find(bad.begin(), bad.end(), 1) == bad.end();
}

}  // namespace focal::detail
