// Welding of STL corners: STL stores every facet with its own three corners, so without welding
// no two triangles share a vertex and no neighbourhood supports a curvature fit.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "focal/core/error.h"
#include "io/detail.h"

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

void weld_corners(Mesh& mesh, double tolerance, bool weld) {
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) {
    throw InvalidInput("read_mesh: weld_tolerance must be finite and >= 0");
  }
  const Eigen::Index corners = mesh.V.rows();
  mesh.corner_vertex.resize(corners);
  if (!weld) {
    for (Eigen::Index i = 0; i < corners; ++i) mesh.corner_vertex(i) = static_cast<int>(i);
    return;
  }
  std::vector<Eigen::Index> first_corner;  // welded vertex -> the corner that defines it
  first_corner.reserve(static_cast<std::size_t>(corners));
  const auto new_vertex = [&](Eigen::Index i) {
    mesh.corner_vertex(i) = static_cast<int>(first_corner.size());
    first_corner.push_back(i);
  };
  std::unordered_map<Key, int, KeyHash> index;
  index.reserve(static_cast<std::size_t>(corners));
  if (tolerance == 0.0) {
    for (Eigen::Index i = 0; i < corners; ++i) {
      if (!finite_row(mesh.V, i)) {  // NaN is equal to nothing: such corners stay apart
        new_vertex(i);
        continue;
      }
      const Key key{bits_of(mesh.V(i, 0)), bits_of(mesh.V(i, 1)), bits_of(mesh.V(i, 2))};
      const auto [it, inserted] = index.try_emplace(key, static_cast<int>(first_corner.size()));
      if (inserted) {
        new_vertex(i);
      } else {
        mesh.corner_vertex(i) = it->second;
      }
    }
  } else {
    // Cells of side `tolerance`: a vertex within `tolerance` of a corner lies in the corner's
    // cell or one of its 26 neighbours. Each cell lists its vertices in creation order, and a
    // corner joins the lowest-numbered vertex within reach, so the result does not depend on
    // the hash table's iteration order.
    std::unordered_map<Key, std::vector<int>, KeyHash> cells;
    const double tolerance2 = tolerance * tolerance;
    for (Eigen::Index i = 0; i < corners; ++i) {
      if (!finite_row(mesh.V, i)) {
        new_vertex(i);
        continue;
      }
      const Key key{cell_of(mesh.V(i, 0), tolerance), cell_of(mesh.V(i, 1), tolerance),
                    cell_of(mesh.V(i, 2), tolerance)};
      int best = std::numeric_limits<int>::max();
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            const auto it = cells.find({key.x + dx, key.y + dy, key.z + dz});
            if (it == cells.end()) continue;
            for (const int v : it->second) {
              if (v >= best) break;
              const double d2 =
                  (mesh.V.row(first_corner[static_cast<std::size_t>(v)]) - mesh.V.row(i))
                      .squaredNorm();
              if (d2 <= tolerance2) best = v;
            }
          }
        }
      }
      if (best != std::numeric_limits<int>::max()) {
        mesh.corner_vertex(i) = best;
      } else {
        cells[key].push_back(static_cast<int>(first_corner.size()));
        new_vertex(i);
      }
    }
  }
  RowMatrixX3d welded(static_cast<Eigen::Index>(first_corner.size()), 3);
  for (std::size_t v = 0; v < first_corner.size(); ++v) {
    welded.row(static_cast<Eigen::Index>(v)) = mesh.V.row(first_corner[v]);
  }
  mesh.V = std::move(welded);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) mesh.F(f, c) = mesh.corner_vertex(mesh.F(f, c));
  }
}

}  // namespace focal::io_detail
