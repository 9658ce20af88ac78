// A vertex's jet points (jet_points.h): its k-ring by breadth-first search over the 1-ring with
// one mark bit per vertex, and the ring's offsets in the vertex's frame.
#include "normals/jet_points.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

namespace focal::detail::jets {
namespace {

/// Two doubles as one SSE2 register: x.q and y.q in gather_points, with the same products and
/// sums per entry (and bits) as one at a time.
using Pair = double __attribute__((vector_size(2 * sizeof(double))));

/// Where the marked vertices of `ring` lie within a few words of marks of each other (on a mesh
/// whose nearby vertices have nearby indices), rewrites `ring` in ascending order by reading
/// those words, clearing them as it goes, and returns true: the sorted ring without a sort.
/// Otherwise leaves both as they are and returns false.
bool read_marks_in_order(std::vector<int>& ring, std::uint64_t* bits) {
  const auto [lowest, highest] = std::minmax_element(ring.begin(), ring.end());
  const auto first = static_cast<std::size_t>(*lowest) / 64;
  const auto last = static_cast<std::size_t>(*highest) / 64;
  if (last - first >= 4 * ring.size()) return false;
  int* out = ring.data();
  for (std::size_t k = first; k <= last; ++k) {
    for (std::uint64_t word = bits[k]; word != 0; word &= word - 1)
      *out++ = static_cast<int>(64 * k) + std::countr_zero(word);
    bits[k] = 0;
  }
  return true;
}

/// Neighbours of one vertex that gather_ring adds between two checks of its cap.
constexpr std::ptrdiff_t kCapRun = 64;

}  // namespace

void gather_ring(const Neighbourhoods& one, int v, int rings, std::vector<std::uint64_t>& in_ring,
                 const std::vector<int>* sort_rows, std::vector<int>& ring) {
  if (in_ring.empty()) in_ring.assign(static_cast<std::size_t>(one.vertex_count()) / 64 + 1, 0);
  std::uint64_t* bits = in_ring.data();
  ring.assign(1, v);
  bits[static_cast<std::size_t>(v) / 64] |= std::uint64_t{1} << (static_cast<unsigned>(v) % 64);
  // Past the cap (rings >= 2) the search stops and v keeps no neighbours: no jet, as k_ring().
  // Past it the ring is dropped either way, so where the search stops does not change a result.
  const std::size_t cap = rings >= 2 ? std::size_t{kMaxNeighbourhoodSize} + 1 : SIZE_MAX;
  std::size_t size = 1;  // the entries of `ring` gathered; the rest is room to write into
  std::size_t begin = 0;
  for (int depth = 0; depth < rings && begin < size && size <= cap; ++depth) {
    const std::size_t end = size;
    // Room for every neighbour of this depth's vertices, or up to the last run past the cap.
    std::size_t room = size;
    for (std::size_t k = begin; k < end; ++k) room += static_cast<std::size_t>(one.size(ring[k]));
    if (rings >= 2) room = std::min(room, cap + static_cast<std::size_t>(kCapRun));
    if (ring.size() < room) ring.resize(room);
    int* const first = ring.data();
    int* out = first + size;
    const auto within_cap = [&] { return static_cast<std::size_t>(out - first) <= cap; };
    for (std::size_t k = begin; k < end && within_cap(); ++k) {
      const int u = first[k];
      // The cap is checked after each run of kCapRun neighbours: the centre of a fan of 100,000
      // corners would otherwise add them all to the ring of each of its 100,000 neighbours.
      for (const int *w = one.begin(u), *last = one.end(u); w != last && within_cap();) {
        const int* const run_end = w + std::min<std::ptrdiff_t>(kCapRun, last - w);
        for (; w != run_end; ++w) {
          // Each neighbour is written; the end moves past it only where it was not marked.
          const int x = *w;
          std::uint64_t& word = bits[static_cast<std::size_t>(x) / 64];
          const std::uint64_t bit = std::uint64_t{1} << (static_cast<unsigned>(x) % 64);
          *out = x;
          out += (word & bit) == 0 ? 1 : 0;
          word |= bit;
        }
      }
    }
    size = static_cast<std::size_t>(out - first);
    begin = end;
  }
  ring.resize(size);
  if (!sort_rows && ring.size() <= cap && read_marks_in_order(ring, bits)) return;
  for (const int w : ring) bits[static_cast<std::size_t>(w) / 64] = 0;  // whole words: cheaper
  if (ring.size() > cap) ring.resize(1);
  if (sort_rows) {
    const int* row = sort_rows->data();
    detail::sort_small(ring.data(), ring.data() + ring.size(),
                       [row](int a, int b) { return row[a] < row[b]; });
  } else {
    detail::sort_small(ring.data(), ring.data() + ring.size(), std::less<>());
  }
}

double gather_points(PositionsRef V, int i, const kernels::Frame<double>& f,
                     const std::vector<int>& ring, Points& points) {
  points.resize(ring.size() + 1);  // room for every point: written through a pointer, no checks
  Point* out = points.data();
  *out++ = {0.0, 0.0, 0.0};
  // Plain scalars: Eigen's 3-vectors pack into an SSE pair plus a scalar, which costs more than
  // the nine products here. x.q and y.q as one pair (the same products and sums per entry):
  // GCC paired them by itself or not, depending on how the frame was built.
  const double px = V(i, 0), py = V(i, 1), pz = V(i, 2);
  const Pair frame_x = {f.x.x, f.y.x}, frame_y = {f.x.y, f.y.y}, frame_z = {f.x.z, f.y.z};
  const double nx = f.n.x, ny = f.n.y, nz = f.n.z;
  double scale_sq = 0.0;
  for (const int j : ring) {
    if (j == i) continue;
    const double qx = V(j, 0) - px, qy = V(j, 1) - py, qz = V(j, 2) - pz;
    // All three finite (x - x is 0 for a finite x, NaN otherwise): one test instead of three.
    if (!((qx - qx) + (qy - qy) + (qz - qz) == 0.0)) continue;
    const Pair tangential = frame_x * qx + frame_y * qy + frame_z * qz;
    *out++ = {tangential[0], tangential[1], nx * qx + ny * qy + nz * qz};
    scale_sq = std::max(scale_sq, qx * qx + qy * qy + qz * qz);
  }
  points.resize(static_cast<std::size_t>(out - points.data()));
  const double scale = std::sqrt(scale_sq);  // the largest |q|: sqrt is monotonic
  if (scale > 0.0) {
    const double inv = 1.0 / scale;
    for (Point& q : points) q = {q.x * inv, q.y * inv, q.z * inv};
  }
  return scale;
}

}  // namespace focal::detail::jets
