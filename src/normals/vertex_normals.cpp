#include "focal/normals/vertex_normals.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/simd_lanes.h"
#include "focal/core/error.h"
#include "kernels/vec3.h"
#include "mesh/prepared_access.h"
#include "mesh/topology.h"
#include "normals/vertex_normals_from.h"

namespace focal {
namespace {

// A weighted sum this much shorter than the sum of its terms' lengths has cancelled out (opposite
// faces, a fold): its direction is rounding noise, so the normal does not exist. Rounding leaves
// about 1e-16 relative; 1e-12 keeps a wide margin yet flags no sum that carries information.
constexpr double kVanishingSum = 1e-12;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Plain scalars rather than Eigen::Vector3d here: Eigen pairs 3-vectors into one SSE2 register
// plus a scalar, and the packing cost more than the arithmetic (a third of vertex_normals).
struct Vec3 {
  double x, y, z;
};

inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

inline Vec3 row(PositionsRef V, Eigen::Index i) { return {V(i, 0), V(i, 1), V(i, 2)}; }

// A face's weighted normal at one corner, and that vector's length.
struct CornerTerm {
  Vec3 normal{0.0, 0.0, 0.0};
  double length = 0.0;
};

// Contribution of a face to the normal at its corner p, with q and r following p
// counter-clockwise; zero for a degenerate face. The weighting is a template parameter so that
// the per-face switch is hoisted out of the vertex loop.
template <NormalWeighting weighting>
CornerTerm corner_contribution(const Vec3& p, const Vec3& q, const Vec3& r) {
  const Vec3 e1 = q - p;
  const Vec3 e2 = r - p;
  const Vec3 n = cross(e1, e2);
  const double n_norm = std::sqrt(dot(n, n));
  const double e1_sq = dot(e1, e1);
  const double e2_sq = dot(e2, e2);
  const Vec3 e3 = r - q;
  // Same test as detail::is_degenerate_triangle, reusing the cross product computed here.
  if (!(n_norm > detail::kDegenerateArea * std::max({e1_sq, e2_sq, dot(e3, e3)}))) return {};
  if constexpr (weighting == NormalWeighting::area) {
    return {n, n_norm};
  } else if constexpr (weighting == NormalWeighting::angle) {
    // atan2 keeps full precision for angles near 0 and pi, unlike acos of a dot product.
    const double angle = std::atan2(n_norm, dot(e1, e2));
    const double scale = angle / n_norm;
    return {{scale * n.x, scale * n.y, scale * n.z}, angle};
  } else {
    const double scale = 1.0 / (e1_sq * e2_sq);
    return {{scale * n.x, scale * n.y, scale * n.z}, scale * n_norm};
  }
}

// Weighted normal of vertex v from its incident faces, in ascending face order; NaN when no face
// contributes or the contributions cancel.
template <NormalWeighting weighting>
Eigen::Vector3d gathered_normal(PositionsRef V, FacesRef F, const detail::VertexFaces& inc,
                                std::int64_t v) {
  Vec3 sum{0.0, 0.0, 0.0};
  double total = 0.0;
  const Vec3 p = row(V, v);
  for (int j = inc.begin(v); j < inc.end(v); ++j) {
    const int f = inc.faces[static_cast<std::size_t>(j)];
    const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
    if (a == b || b == c || a == c) continue;  // a repeated index spans no triangle
    // The corners following v counter-clockwise.
    const int q = a == v ? b : (b == v ? c : a);
    const int r = a == v ? c : (b == v ? a : b);
    const CornerTerm term = corner_contribution<weighting>(p, row(V, q), row(V, r));
    sum = {sum.x + term.normal.x, sum.y + term.normal.y, sum.z + term.normal.z};
    total += term.length;
  }
  const double length = std::sqrt(dot(sum, sum));
  if (!(length > kVanishingSum * total)) return Eigen::Vector3d::Constant(kNaN);
  return {sum.x / length, sum.y / length, sum.z / length};
}

// ---- Area- and Max-weighted normals of several vertices side by side, one vertex per lane
// (core/simd_lanes.h): lane l adds its vertex's k-th face at step k, in the scalar loop's order
// and with its operations, so each lane has gathered_normal's bits. A lane with no k-th face, or
// whose k-th face repeats an index, takes its own vertex as both other corners: a degenerate
// corner, which adds +0, and +0 leaves the sums' bits (they start at +0 and never become -0).
// The angle weighting stays scalar (no atan2 in lanes).

/// A 3-vector of lanes (this file's Vec3 is the scalar one).
template <class L>
using Lanes3 = kernels::Vec3<L>;

/// The corners following v counter-clockwise in face f, or v twice where f repeats an index.
inline void following_corners(FacesRef F, int f, int v, int& q, int& r) {
  const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
  if (a == b || b == c || a == c) {
    q = r = v;
    return;
  }
  q = a == v ? b : (b == v ? c : a);
  r = a == v ? c : (b == v ? a : b);
}

template <class L>
FOCAL_LANE_INLINE Lanes3<L> rows_of(PositionsRef V, const int (&i)[detail::lane_count<L>]) {
  return {detail::lanes_of<L>([&](int l) { return V(i[l], 0); }),
          detail::lanes_of<L>([&](int l) { return V(i[l], 1); }),
          detail::lanes_of<L>([&](int l) { return V(i[l], 2); })};
}

/// corner_contribution per lane, added to sum and total (+0 where it is degenerate).
template <NormalWeighting weighting, class L>
FOCAL_LANE_INLINE void add_corner(const Lanes3<L>& p, const Lanes3<L>& q, const Lanes3<L>& r,
                                  Lanes3<L>& sum, L& total) {
  using kernels::dot;
  const Lanes3<L> e1 = q - p, e2 = r - p;
  const Lanes3<L> n = kernels::cross(e1, e2);
  const L n_norm = kernels::sqrt_of(dot(n, n));
  const L e1_sq = dot(e1, e1), e2_sq = dot(e2, e2);
  const Lanes3<L> e3 = r - q;
  // std::max({a, b, c}) with its comparisons (max_of), so a NaN is kept or dropped alike.
  const L longest = kernels::max_of(kernels::max_of(e1_sq, e2_sq), dot(e3, e3));
  const auto kept = n_norm > detail::kDegenerateArea * longest;
  Lanes3<L> term = n;
  L length = n_norm;
  if constexpr (weighting == NormalWeighting::max) {
    const L scale = 1.0 / (e1_sq * e2_sq);
    term = scale * n, length = scale * n_norm;
  }
  const L zero{};
  sum = {sum.x + (kept ? term.x : zero), sum.y + (kept ? term.y : zero),
         sum.z + (kept ? term.z : zero)};
  total += kept ? length : zero;
}

/// gathered_normal of vertices [first, first + active) into their rows of N.
template <NormalWeighting weighting, class L>
FOCAL_LANE_INLINE void gather_normal_group(PositionsRef V, FacesRef F,
                                           const detail::VertexFaces& inc, std::int64_t first,
                                           int active, RowMatrixX3d& N) {
  constexpr int W = detail::lane_count<L>;
  int v[W], count[W], most = 0;
  for (int l = 0; l < W; ++l) {
    v[l] = static_cast<int>(first + std::min(l, active - 1));
    count[l] = inc.size(v[l]);
    most = std::max(most, count[l]);
  }
  const Lanes3<L> p = rows_of<L>(V, v);
  Lanes3<L> sum{L{}, L{}, L{}};
  L total{};
  for (int k = 0; k < most; ++k) {
    int q[W], r[W];
    for (int l = 0; l < W; ++l) {
      q[l] = r[l] = v[l];
      if (k < count[l]) {
        following_corners(F, inc.faces[static_cast<std::size_t>(inc.begin(v[l]) + k)], v[l], q[l],
                          r[l]);
      }
    }
    add_corner<weighting>(p, rows_of<L>(V, q), rows_of<L>(V, r), sum, total);
  }
  const L length = kernels::sqrt_of(kernels::dot(sum, sum));
  const auto exists = length > kVanishingSum * total;
  const L nan = detail::broadcast<L>(kNaN);
  const L x = exists ? sum.x / length : nan, y = exists ? sum.y / length : nan;
  const L z = exists ? sum.z / length : nan;
  for (int l = 0; l < active; ++l)
    N(first + l, 0) = x[l], N(first + l, 1) = y[l], N(first + l, 2) = z[l];
}

template <NormalWeighting weighting, class L>
FOCAL_LANE_INLINE void gather_normal_block(PositionsRef V, FacesRef F,
                                           const detail::VertexFaces& inc, std::int64_t begin,
                                           std::int64_t end, RowMatrixX3d& N) {
  constexpr int W = detail::lane_count<L>;
  for (std::int64_t first = begin; first < end; first += W) {
    gather_normal_group<weighting, L>(V, F, inc, first,
                                      static_cast<int>(std::min<std::int64_t>(W, end - first)), N);
  }
}

template <NormalWeighting weighting>
FOCAL_TARGET_AVX512 void gather_normal_block_avx512(PositionsRef V, FacesRef F,
                                                    const detail::VertexFaces& inc,
                                                    std::int64_t begin, std::int64_t end,
                                                    RowMatrixX3d& N) {
  gather_normal_block<weighting, detail::Lanes8>(V, F, inc, begin, end, N);
}
template <NormalWeighting weighting>
FOCAL_TARGET_AVX2 void gather_normal_block_avx2(PositionsRef V, FacesRef F,
                                                const detail::VertexFaces& inc, std::int64_t begin,
                                                std::int64_t end, RowMatrixX3d& N) {
  gather_normal_block<weighting, detail::Lanes4>(V, F, inc, begin, end, N);
}
template <NormalWeighting weighting>
void gather_normal_block_baseline(PositionsRef V, FacesRef F, const detail::VertexFaces& inc,
                                  std::int64_t begin, std::int64_t end, RowMatrixX3d& N) {
  gather_normal_block<weighting, detail::Lanes2>(V, F, inc, begin, end, N);
}

/// The normals of every vertex: in the lanes of `isa` where the weighting has a lane kernel,
/// one vertex at a time otherwise or without `isa` (the reference the lanes are tested against).
template <NormalWeighting weighting>
void gather_normals(PositionsRef V, FacesRef F, const detail::VertexFaces& inc, int threads,
                    std::optional<detail::SimdIsa> isa, RowMatrixX3d& N) {
  if constexpr (weighting != NormalWeighting::angle) {
    if (isa) {
      const auto block = detail::kernel_for(*isa, gather_normal_block_avx512<weighting>,
                                            gather_normal_block_avx2<weighting>,
                                            gather_normal_block_baseline<weighting>);
      // Each vertex's row is computed alone: blocks and threads change no bit.
      detail::parallel_for_blocks(
          V.rows(), 1024, threads,
          [&](std::int64_t begin, std::int64_t end) { block(V, F, inc, begin, end, N); });
      return;
    }
  }
  detail::parallel_for(V.rows(), threads, [&](std::int64_t v) {
    N.row(v) = gathered_normal<weighting>(V, F, inc, v).transpose();
  });
}

}  // namespace

RowMatrixX3d vertex_normals(PositionsRef V, FacesRef F, NormalWeighting weighting) {
  return vertex_normals(detail::PreparedAccess::make(V, F, std::nullopt, {}, "vertex_normals"),
                        weighting);
}

RowMatrixX3d vertex_normals(const PreparedMesh& mesh, NormalWeighting weighting) {
  return detail::vertex_normals_from(mesh.V(), mesh.F(), *detail::incidence(mesh), weighting, 0);
}

namespace detail {

RowMatrixX3d vertex_normals_from(PositionsRef V, FacesRef F, const VertexFaces& inc,
                                 NormalWeighting weighting, int threads,
                                 std::optional<SimdIsa> isa) {
  RowMatrixX3d N(V.rows(), 3);
  switch (weighting) {
    case NormalWeighting::area:
      gather_normals<NormalWeighting::area>(V, F, inc, threads, isa, N);
      break;
    case NormalWeighting::angle:
      gather_normals<NormalWeighting::angle>(V, F, inc, threads, isa, N);
      break;
    case NormalWeighting::max:
      gather_normals<NormalWeighting::max>(V, F, inc, threads, isa, N);
      break;
  }
  return N;
}

}  // namespace detail

double fraction_against_faces(PositionsRef V, FacesRef F, NormalsRef N) {
  const PreparedMesh mesh = detail::PreparedAccess::make(V, F, N, {}, "fraction_against_faces");
  // NaN rows (no face, or a vanishing sum) drop out through the finiteness test below.
  const RowMatrixX3d face_normals = vertex_normals(mesh, NormalWeighting::area);
  std::int64_t counted = 0;
  std::int64_t against = 0;
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    if (!N.row(v).allFinite() || !face_normals.row(v).allFinite()) continue;
    ++counted;
    if (N.row(v).dot(face_normals.row(v)) < 0.0) ++against;
  }
  if (counted == 0) return kNaN;
  return static_cast<double>(against) / static_cast<double>(counted);
}

}  // namespace focal
