#include "focal/mesh/normals.h"

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
#include "mesh/normals_detail.h"
#include "mesh/prepared_detail.h"
#include "mesh/statistics_detail.h"
#include "mesh/topology.h"

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

RowMatrixX3d vertex_normals(PositionsRef V, FacesRef F, NormalWeighting weighting, int threads) {
  return vertex_normals(
      detail::PreparedAccess::make(V, F, std::nullopt, {.threads = threads}, "vertex_normals"),
      weighting);
}

RowMatrixX3d vertex_normals(const PreparedMesh& mesh, NormalWeighting weighting) {
  return detail::vertex_normals_from(mesh.V(), mesh.F(), *detail::incidence(mesh), weighting,
                                     mesh.threads());
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

int OrientationReport::inward_count() const {
  int count = 0;
  for (const auto& c : components) count += c.inward ? 1 : 0;
  return count;
}

namespace {

// Per-component tallies over the vertices: count, open / inconsistent edges at them, and the sum
// of their positions (for the centroid).
struct VertexTally {
  int count = 0;
  bool open = false;
  bool inconsistent = false;
  Vec3 sum{0.0, 0.0, 0.0};

  VertexTally& operator+=(const VertexTally& o) {
    count += o.count;
    open = open || o.open;
    inconsistent = inconsistent || o.inconsistent;
    sum = {sum.x + o.sum.x, sum.y + o.sum.y, sum.z + o.sum.z};
    return *this;
  }
};

// Per-component tallies over the faces: count and signed volume about the component's centroid.
struct FaceTally {
  int count = 0;
  double volume = 0.0;

  FaceTally& operator+=(const FaceTally& o) {
    count += o.count;
    volume += o.volume;
    return *this;
  }
};

}  // namespace

OrientationReport orientation_report(PositionsRef V, FacesRef F, int threads) {
  return orientation_report(
      detail::PreparedAccess::make(V, F, std::nullopt, {.threads = threads}, "orientation_report"));
}

OrientationReport orientation_report(const PreparedMesh& mesh) {
  const int threads = mesh.threads();
  return detail::orientation_report_from(
      mesh.V(), mesh.F(),
      detail::mesh_topology(*detail::incidence(mesh), mesh.F(), detail::TopologyDetail::orientation,
                            threads),
      threads);
}

// Signed volumes are taken per component about its vertex centroid: for a surface far from the
// origin the determinants would otherwise be large terms that cancel. Both passes are parallel
// (detail::add_by_key_runs: per-block runs added in block order, the same for any thread count).
OrientationReport detail::orientation_report_from(PositionsRef V, FacesRef F, const MeshTopology& t,
                                                  int threads) {
  const FaceComponents& comp = t.components;
  const auto count = static_cast<std::size_t>(comp.count);
  std::vector<VertexTally> vertices(count);
  add_by_key_runs(
      static_cast<std::int64_t>(t.edge_flags.size()), threads,
      [&](std::int64_t v) { return comp.vertex_component[static_cast<std::size_t>(v)]; },
      [&](VertexTally& tally, std::int64_t v) {
        const std::uint8_t flags = t.edge_flags[static_cast<std::size_t>(v)];
        ++tally.count;
        tally.open = tally.open || (flags & kOpenEdge) != 0;
        tally.inconsistent = tally.inconsistent || (flags & kInconsistentEdge) != 0;
        tally.sum = {tally.sum.x + V(v, 0), tally.sum.y + V(v, 1), tally.sum.z + V(v, 2)};
      },
      vertices);
  std::vector<Vec3> centroid(count);
  for (std::size_t c = 0; c < count; ++c) {
    const double n = static_cast<double>(vertices[c].count);
    centroid[c] = {vertices[c].sum.x / n, vertices[c].sum.y / n, vertices[c].sum.z / n};
  }
  std::vector<FaceTally> faces(count);
  add_by_key_runs(
      F.rows(), threads,
      [&](std::int64_t f) { return comp.face_component[static_cast<std::size_t>(f)]; },
      [&](FaceTally& tally, std::int64_t f) {
        const Vec3& o =
            centroid[static_cast<std::size_t>(comp.face_component[static_cast<std::size_t>(f)])];
        const Vec3 a = row(V, F(f, 0)) - o, b = row(V, F(f, 1)) - o, d = row(V, F(f, 2)) - o;
        ++tally.count;
        tally.volume += dot(a, cross(b, d)) / 6.0;
      },
      faces);
  OrientationReport report;
  report.face_component = Eigen::Map<const Eigen::VectorXi>(comp.face_component.data(), F.rows());
  report.components.resize(count);
  for (std::size_t c = 0; c < count; ++c) {
    ComponentOrientation& out = report.components[c];
    out.face_count = faces[c].count;
    out.vertex_count = vertices[c].count;
    out.closed = !vertices[c].open;
    out.consistent = !vertices[c].inconsistent;
    out.signed_volume = faces[c].volume;
    out.inward = out.closed && out.consistent && out.signed_volume < 0.0;
  }
  return report;
}

RowMatrixX3i orient_outward(FacesRef F, const OrientationReport& report) {
  if (report.face_component.size() != F.rows()) {
    throw InvalidInput("orient_outward: the orientation report covers " +
                       std::to_string(report.face_component.size()) + " faces, but F has " +
                       std::to_string(F.rows()));
  }
  RowMatrixX3i out = F;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const int c = report.face_component[f];
    if (c < 0 || c >= static_cast<int>(report.components.size())) {
      throw InvalidInput("orient_outward: face " + std::to_string(f) + " has component " +
                         std::to_string(c) + ", but the report has " +
                         std::to_string(report.components.size()) + " components");
    }
    if (report.components[static_cast<std::size_t>(c)].inward) std::swap(out(f, 1), out(f, 2));
  }
  return out;
}

namespace {

// Face-to-face links across interior edges. Slot 3 f + c stands for the edge from corner c to
// corner c + 1 of face f: the face across it (-1 if none) and whether that face traverses the
// edge the same way, so that one of the two has to be reversed.
struct FaceLinks {
  std::vector<int> across;
  std::vector<std::uint8_t> same;
};

// Slot of face f's edge {a, b}; f has both as corners and no repeated index.
std::size_t edge_slot(FacesRef F, int f, int a, int b) {
  int c = 0;
  while (!((F(f, c) == a && F(f, (c + 1) % 3) == b) || (F(f, c) == b && F(f, (c + 1) % 3) == a))) {
    ++c;
  }
  return 3 * static_cast<std::size_t>(f) + static_cast<std::size_t>(c);
}

// Each interior edge is linked by its lower vertex only and each slot belongs to one edge, so the
// parallel writes never collide and the result does not depend on the thread count.
FaceLinks face_links(std::int64_t vertex_count, FacesRef F, const detail::VertexFaces& inc,
                     int threads) {
  FaceLinks links;
  links.across.assign(3 * static_cast<std::size_t>(F.rows()), -1);
  links.same.assign(3 * static_cast<std::size_t>(F.rows()), 0);
  detail::PerThread<std::vector<detail::EdgeSide>> scratch(threads);
  detail::parallel_for(vertex_count, threads, [&](std::int64_t v) {
    auto& sides = scratch.local();
    detail::collect_edge_sides(F, inc, v, sides);
    detail::for_each_edge(sides, [&](int other, const detail::EdgeSide* first,
                                     const detail::EdgeSide* last) {
      // Faces with a repeated index (direction 0) have no orientation to agree with.
      if (other < v || last - first != 2 || first[0].direction == 0 || first[1].direction == 0) {
        return;
      }
      const auto face = [&](const detail::EdgeSide& side) {
        return inc.faces[static_cast<std::size_t>(inc.begin(v) + side.local_face)];
      };
      const int f = face(first[0]), g = face(first[1]);
      const std::uint8_t same = first[0].direction == first[1].direction ? 1 : 0;
      const int a = static_cast<int>(v);
      const std::size_t fs = edge_slot(F, f, a, other), gs = edge_slot(F, g, a, other);
      links.across[fs] = g;
      links.across[gs] = f;
      links.same[fs] = links.same[gs] = same;
    });
  });
  return links;
}

// Flip flags per face: breadth-first search over the links from each patch's lowest-index face,
// then the whole patch inverted when that reverses fewer faces.
std::vector<std::uint8_t> consistent_flips(const FaceLinks& links, std::size_t face_count) {
  std::vector<std::uint8_t> flip(face_count, 0);
  std::vector<std::uint8_t> seen(face_count, 0);
  std::vector<int> patch;  // also the search queue
  for (std::size_t seed = 0; seed < face_count; ++seed) {
    if (seen[seed]) continue;
    seen[seed] = 1;
    patch.assign(1, static_cast<int>(seed));
    std::size_t flipped = 0;
    for (std::size_t q = 0; q < patch.size(); ++q) {
      const auto f = static_cast<std::size_t>(patch[q]);
      for (std::size_t slot = 3 * f; slot < 3 * f + 3; ++slot) {
        const int g = links.across[slot];
        if (g < 0 || seen[static_cast<std::size_t>(g)]) continue;
        seen[static_cast<std::size_t>(g)] = 1;
        flip[static_cast<std::size_t>(g)] = flip[f] ^ links.same[slot];
        flipped += flip[static_cast<std::size_t>(g)];
        patch.push_back(g);
      }
    }
    if (2 * flipped > patch.size()) {
      for (const int f : patch) flip[static_cast<std::size_t>(f)] ^= 1;
    }
  }
  return flip;
}

}  // namespace

ConsistentFaces orient_consistently(int vertex_count, FacesRef F, int threads) {
  detail::check_face_indices(vertex_count, F, "orient_consistently");
  const auto inc = detail::vertex_face_incidence(vertex_count, F, threads);
  const FaceLinks links = face_links(vertex_count, F, inc, threads);
  const auto face_count = static_cast<std::size_t>(F.rows());
  const std::vector<std::uint8_t> flip = consistent_flips(links, face_count);

  ConsistentFaces result;
  result.F = F;
  for (std::size_t f = 0; f < face_count; ++f) {
    if (!flip[f]) continue;
    std::swap(result.F(static_cast<Eigen::Index>(f), 1), result.F(static_cast<Eigen::Index>(f), 2));
    ++result.flipped_face_count;
  }
  for (std::size_t slot = 0; slot < links.across.size(); ++slot) {
    const int g = links.across[slot];
    const std::size_t f = slot / 3;
    // Each edge once, from its lower face.
    if (g > static_cast<int>(f) &&
        (links.same[slot] ^ flip[f] ^ flip[static_cast<std::size_t>(g)])) {
      ++result.conflicting_edge_count;
    }
  }
  return result;
}

double fraction_against_faces(PositionsRef V, FacesRef F, NormalsRef N, int threads) {
  const PreparedMesh mesh =
      detail::PreparedAccess::make(V, F, N, {.threads = threads}, "fraction_against_faces");
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
