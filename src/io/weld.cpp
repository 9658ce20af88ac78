// Welding of STL corners: STL stores every facet with its own three corners, so without welding
// no two triangles share a vertex and no neighbourhood supports a curvature fit.

#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "io/format_readers.h"

namespace focal::io_detail {
namespace {

struct Key {
  std::int64_t x, y, z;
  bool operator==(const Key&) const = default;
};

struct KeyHash {
  std::size_t operator()(const Key& k) const {
    // Mix the three words (splitmix64 finaliser): bit patterns of nearby floats differ only in
    // their low bits.
    std::uint64_t h = static_cast<std::uint64_t>(k.x);
    h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ULL + static_cast<std::uint64_t>(k.y);
    h = (h ^ (h >> 27)) * 0x94d049bb133111ebULL + static_cast<std::uint64_t>(k.z);
    h ^= h >> 31;
    return static_cast<std::size_t>(h);
  }
};

/// The bit pattern of x, with -0.0 read as 0.0 (they are the same position).
std::int64_t bits_of(double x) {
  const double y = x + 0.0;  // -0.0 + 0.0 == +0.0
  std::int64_t b = 0;
  std::memcpy(&b, &y, sizeof b);
  return b;
}

bool finite_row(const RowMatrixX3d& V, Eigen::Index i) {
  return std::isfinite(V(i, 0)) && std::isfinite(V(i, 1)) && std::isfinite(V(i, 2));
}

/// Grid cell of one coordinate, clamped so that huge coordinates or tiny tolerances cannot
/// overflow (clamped cells only weld corners that are within tolerance anyway: the distance is
/// checked).
std::int64_t cell_of(double x, double tolerance) {
  constexpr double kLimit = 4.0e18;
  const double q = std::floor(x / tolerance);
  if (!(q > -kLimit)) return static_cast<std::int64_t>(-kLimit);
  if (!(q < kLimit)) return static_cast<std::int64_t>(kLimit);
  return static_cast<std::int64_t>(q);
}

}  // namespace

namespace {

constexpr std::int32_t kEmpty = -1;
constexpr std::int64_t kCornerBlock = 65536;  // corners per block of the parallel passes
constexpr int kBucketBits = 10;               // 1024 buckets of corners, by their key's hash

Key exact_key(const RowMatrixX3d& V, Eigen::Index i) {
  return {bits_of(V(i, 0)), bits_of(V(i, 1)), bits_of(V(i, 2))};
}

/// The hash of corner i's exact key; no bucket for a non-finite corner.
std::uint64_t corner_hash(const RowMatrixX3d& V, std::int64_t i) {
  return KeyHash{}(exact_key(V, i));
}

/// The finite corners sorted by bucket (the top kBucketBits of their hash), ascending within a
/// bucket, with their hashes beside them, and where each bucket starts (buckets + 1 offsets). A
/// counting sort over blocks of corners: block-major offsets keep each bucket in corner order.
/// The scatter pass hashes each corner again rather than keeping the count pass's hashes (48 MB at
/// 6M corners, for a hash that costs a few instructions).
struct Buckets {
  std::vector<std::int32_t> corner;
  std::vector<std::uint64_t> hash;
  std::vector<std::int64_t> start;
};

Buckets sort_into_buckets(const RowMatrixX3d& V, int threads) {
  constexpr std::int64_t kBuckets = std::int64_t{1} << kBucketBits;
  const auto n = static_cast<std::int64_t>(V.rows());
  const std::int64_t blocks = (n + kCornerBlock - 1) / kCornerBlock;
  std::vector<std::int64_t> offset(static_cast<std::size_t>(blocks * kBuckets), 0);
  detail::parallel_for_blocks(n, kCornerBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    std::int64_t* count = offset.data() + begin / kCornerBlock * kBuckets;
    for (auto i = begin; i < end; ++i) {
      if (finite_row(V, i)) ++count[corner_hash(V, i) >> (64 - kBucketBits)];
    }
  });
  Buckets buckets;
  buckets.start.assign(kBuckets + 1, 0);
  std::int64_t total = 0;
  for (std::int64_t b = 0; b < kBuckets; ++b) {
    buckets.start[b] = total;
    for (std::int64_t k = 0; k < blocks; ++k) {
      const std::int64_t count = offset[k * kBuckets + b];
      offset[k * kBuckets + b] = total;
      total += count;
    }
  }
  buckets.start[kBuckets] = total;
  buckets.corner.resize(static_cast<std::size_t>(total));
  buckets.hash.resize(static_cast<std::size_t>(total));
  detail::parallel_for_blocks(n, kCornerBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    std::int64_t* next = offset.data() + begin / kCornerBlock * kBuckets;
    for (auto i = begin; i < end; ++i) {
      if (!finite_row(V, i)) continue;
      const std::uint64_t hash = corner_hash(V, i);
      const std::int64_t k = next[hash >> (64 - kBucketBits)]++;
      buckets.corner[k] = static_cast<std::int32_t>(i);
      buckets.hash[k] = hash;
    }
  });
  return buckets;
}

/// first[i] for the corners of each bucket, scanned in corner order with an open-addressing
/// table of its own (positions in the bucket), so the answer depends on neither the buckets nor
/// the thread count. `ComparePositions` false: equal hashes are taken for equal positions, which
/// reads nothing but the bucket's own arrays (in cache); the caller checks the matches.
template <bool ComparePositions>
void match_in_buckets(const RowMatrixX3d& V, const Buckets& buckets, int threads,
                      std::vector<std::int32_t>& first) {
  const auto bucket_count = static_cast<std::int64_t>(buckets.start.size()) - 1;
  detail::parallel_chunks(bucket_count, threads, [&](std::int64_t b) {
    const std::int64_t begin = buckets.start[b];
    const std::int64_t size = buckets.start[b + 1] - begin;
    if (size == 0) return;
    const std::uint64_t mask = std::bit_ceil(static_cast<std::uint64_t>(2 * size)) - 1;
    std::vector<std::int32_t> table(mask + 1, kEmpty);  // position in the bucket, or kEmpty
    const std::uint64_t* hash = buckets.hash.data() + begin;
    const std::int32_t* corner = buckets.corner.data() + begin;
    for (std::int32_t k = 0; k < size; ++k) {
      for (std::uint64_t slot = hash[k] & mask;; slot = (slot + 1) & mask) {
        const std::int32_t held = table[slot];
        if (held == kEmpty) {
          table[slot] = k;
          break;
        }
        if (hash[held] == hash[k] &&
            (!ComparePositions || exact_key(V, corner[held]) == exact_key(V, corner[k]))) {
          first[corner[k]] = corner[held];
          break;
        }
      }
    }
  });
}

/// Whether every corner matched to an earlier one has exactly its position.
bool matches_are_equal(const RowMatrixX3d& V, const std::vector<std::int32_t>& first, int threads) {
  const auto n = static_cast<std::int64_t>(V.rows());
  std::atomic<bool> equal{true};
  detail::parallel_for_blocks(n, kCornerBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    for (auto i = begin; i < end; ++i) {
      if (first[i] != i && !(exact_key(V, i) == exact_key(V, first[i]))) {
        equal.store(false, std::memory_order_relaxed);
        return;
      }
    }
  });
  return equal.load();
}

}  // namespace

std::vector<std::int32_t> first_equal_corners(const RowMatrixX3d& V, int threads,
                                              bool hashes_first) {
  const auto n = static_cast<std::int64_t>(V.rows());
  std::vector<std::int32_t> first(static_cast<std::size_t>(n));
  const auto reset = [&] {
    detail::parallel_for(n, threads,
                         [&](std::int64_t i) { first[i] = static_cast<std::int32_t>(i); });
  };
  reset();
  const Buckets buckets = sort_into_buckets(V, threads);
  if (hashes_first) {
    // A 64-bit hash shared by two different positions is rare (about 1e-8 at 1M positions) but
    // possible: the matches are checked, and the positions compared throughout if one is wrong.
    match_in_buckets<false>(V, buckets, threads, first);
    if (matches_are_equal(V, first, threads)) return first;
    reset();
  }
  match_in_buckets<true>(V, buckets, threads, first);
  return first;
}

namespace {

/// The weld within `tolerance` > 0: for every corner, the first corner of the vertex it joins
/// (itself when it starts a vertex). Cells of side `tolerance`: a vertex within `tolerance` of a
/// corner lies in the corner's cell or one of its 26 neighbours. Each cell lists its vertices in
/// creation order, and a corner joins the lowest-numbered vertex within reach, so the result
/// does not depend on the hash table's iteration order.
std::vector<std::int32_t> first_near_corners(const RowMatrixX3d& V, double tolerance) {
  const Eigen::Index corners = V.rows();
  std::vector<std::int32_t> first(static_cast<std::size_t>(corners));
  std::vector<std::int32_t> vertex_corner;  // vertex -> the corner that defines it
  std::unordered_map<Key, std::vector<int>, KeyHash> cells;
  const double tolerance2 = tolerance * tolerance;
  for (Eigen::Index i = 0; i < corners; ++i) {
    first[i] = static_cast<std::int32_t>(i);
    if (!finite_row(V, i)) continue;
    const Key key{cell_of(V(i, 0), tolerance), cell_of(V(i, 1), tolerance),
                  cell_of(V(i, 2), tolerance)};
    int best = std::numeric_limits<int>::max();
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells.find({key.x + dx, key.y + dy, key.z + dz});
          if (it == cells.end()) continue;
          for (const int v : it->second) {
            if (v >= best) break;
            const double d2 =
                (V.row(vertex_corner[static_cast<std::size_t>(v)]) - V.row(i)).squaredNorm();
            if (d2 <= tolerance2) best = v;
          }
        }
      }
    }
    if (best != std::numeric_limits<int>::max()) {
      first[i] = vertex_corner[static_cast<std::size_t>(best)];
    } else {
      cells[key].push_back(static_cast<int>(vertex_corner.size()));
      vertex_corner.push_back(static_cast<std::int32_t>(i));
    }
  }
  return first;
}

/// Numbers the vertices in the order of their first corners, fills mesh.corner_vertex, replaces
/// V by the vertices and remaps F. `first[i] <= i` is the first corner of corner i's vertex.
void apply_weld(Mesh& mesh, const std::vector<std::int32_t>& first, int threads) {
  const auto n = static_cast<std::int64_t>(mesh.V.rows());
  const std::int64_t blocks = (n + kCornerBlock - 1) / kCornerBlock;
  std::vector<std::int64_t> vertices_before(static_cast<std::size_t>(blocks) + 1, 0);
  detail::parallel_for_blocks(n, kCornerBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    std::int64_t count = 0;
    for (auto i = begin; i < end; ++i) count += first[i] == i ? 1 : 0;
    vertices_before[begin / kCornerBlock + 1] = count;
  });
  for (std::int64_t k = 0; k < blocks; ++k) vertices_before[k + 1] += vertices_before[k];
  mesh.corner_vertex.resize(n);
  RowMatrixX3d welded(vertices_before[blocks], 3);
  detail::parallel_for_blocks(n, kCornerBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    std::int64_t v = vertices_before[begin / kCornerBlock];
    for (auto i = begin; i < end; ++i) {
      if (first[i] != i) continue;
      mesh.corner_vertex(i) = static_cast<int>(v);
      welded.row(v++) = mesh.V.row(i);
    }
  });
  // A later corner reads its first corner's vertex, set above (first[i] <= i, itself a first).
  detail::parallel_for(n, threads, [&](std::int64_t i) {
    if (first[i] != i) mesh.corner_vertex(i) = mesh.corner_vertex(first[i]);
  });
  mesh.V = std::move(welded);
  detail::parallel_for(mesh.F.rows(), threads, [&](std::int64_t f) {
    for (int c = 0; c < 3; ++c) mesh.F(f, c) = mesh.corner_vertex(mesh.F(f, c));
  });
}

}  // namespace

void weld_corners(Mesh& mesh, double tolerance, bool weld, int threads) {
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) {
    throw InvalidInput("read_mesh: weld_tolerance must be finite and >= 0");
  }
  if (!weld) {
    mesh.corner_vertex.resize(mesh.V.rows());
    for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) mesh.corner_vertex(i) = static_cast<int>(i);
    return;
  }
  apply_weld(mesh,
             tolerance == 0.0 ? first_equal_corners(mesh.V, threads, true)
                              : first_near_corners(mesh.V, tolerance),
             threads);
}

}  // namespace focal::io_detail
