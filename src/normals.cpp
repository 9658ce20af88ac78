#include "focal/normals.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "focal/error.h"
#include "parallel.h"
#include "topology_incidence.h"

namespace focal {
namespace {

// A weighted sum this much shorter than the sum of its terms' lengths has cancelled out (opposite
// faces, a fold): its direction is rounding noise, so the normal does not exist. Rounding leaves
// about 1e-16 relative; 1e-12 keeps a wide margin yet flags no sum that carries information.
constexpr double kVanishingSum = 1e-12;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A face's weighted normal at one corner, and that vector's length.
struct CornerTerm {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double length = 0.0;
};

// Contribution of a face to the normal at its corner p, with q and r following p
// counter-clockwise; zero for a degenerate face.
CornerTerm corner_contribution(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                               const Eigen::Vector3d& r, NormalWeighting weighting) {
  const Eigen::Vector3d e1 = q - p;
  const Eigen::Vector3d e2 = r - p;
  const Eigen::Vector3d n = e1.cross(e2);
  const double n_norm = n.norm();
  const double e1_sq = e1.squaredNorm();
  const double e2_sq = e2.squaredNorm();
  // Same test as detail::is_degenerate_triangle, reusing the cross product computed here.
  if (!(n_norm > detail::kDegenerateArea * std::max({e1_sq, e2_sq, (r - q).squaredNorm()}))) {
    return {};
  }
  switch (weighting) {
    case NormalWeighting::area:
      return {n, n_norm};
    case NormalWeighting::angle: {
      // atan2 keeps full precision for angles near 0 and pi, unlike acos of a dot product.
      const double angle = std::atan2(n_norm, e1.dot(e2));
      return {angle / n_norm * n, angle};
    }
    case NormalWeighting::max: {
      const double scale = 1.0 / (e1_sq * e2_sq);
      return {scale * n, scale * n_norm};
    }
  }
  return {};
}

// Weighted normal of vertex v from its incident faces, in ascending face order; NaN when no face
// contributes or the contributions cancel.
Eigen::Vector3d gathered_normal(PositionsRef V, FacesRef F, const detail::VertexFaces& inc,
                                std::int64_t v, NormalWeighting weighting) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (int j = inc.begin(v); j < inc.end(v); ++j) {
    const int f = inc.faces[static_cast<std::size_t>(j)];
    if (detail::has_repeated_index(F, f)) continue;
    const int c = F(f, 0) == v ? 0 : (F(f, 1) == v ? 1 : 2);
    const CornerTerm term =
        corner_contribution(V.row(v).transpose(), V.row(F(f, (c + 1) % 3)).transpose(),
                            V.row(F(f, (c + 2) % 3)).transpose(), weighting);
    sum += term.normal;
    total += term.length;
  }
  const double length = sum.norm();
  if (!(length > kVanishingSum * total)) return Eigen::Vector3d::Constant(kNaN);
  return sum / length;
}

}  // namespace

RowMatrixX3d vertex_normals(PositionsRef V, FacesRef F, NormalWeighting weighting) {
  validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), "vertex_normals");
  const auto inc = detail::vertex_face_incidence(V.rows(), F);
  RowMatrixX3d N(V.rows(), 3);
  detail::parallel_for(V.rows(), 0, [&](std::int64_t v) {
    N.row(v) = gathered_normal(V, F, inc, v, weighting).transpose();
  });
  return N;
}

int OrientationReport::inward_count() const {
  int count = 0;
  for (const auto& c : components) count += c.inward ? 1 : 0;
  return count;
}

namespace {

// Per-vertex edge findings, for the edges from a vertex to its higher-indexed neighbours (so that
// each edge is examined once).
enum EdgeFlag : std::uint8_t {
  kOpenEdge = 1,          // an edge without exactly two incident faces
  kInconsistentEdge = 2,  // an interior edge traversed the same way by both faces
};

std::vector<std::uint8_t> edge_flags(std::int64_t vertex_count, FacesRef F,
                                     const detail::VertexFaces& inc) {
  std::vector<std::uint8_t> flags(static_cast<std::size_t>(vertex_count), 0);
  detail::PerThread<std::vector<detail::EdgeSide>> scratch;
  detail::parallel_for(vertex_count, 0, [&](std::int64_t v) {
    auto& sides = scratch.local();
    detail::collect_edge_sides(F, inc, v, sides);
    std::uint8_t flag = 0;
    detail::for_each_edge(
        sides, [&](int other, const detail::EdgeSide* first, const detail::EdgeSide* last) {
          if (other < v) return;
          if (last - first != 2) {
            flag |= kOpenEdge;
          } else if (!detail::is_consistent_interior_edge(first, last)) {
            flag |= kInconsistentEdge;
          }
        });
    flags[static_cast<std::size_t>(v)] = flag;
  });
  return flags;
}

// Signed volumes per component, each about its vertex centroid: for a surface far from the origin
// the determinants would otherwise be large terms that cancel.
void add_signed_volumes(PositionsRef V, FacesRef F, const detail::FaceComponents& comp,
                        std::vector<ComponentOrientation>& components) {
  std::vector<Eigen::Vector3d> centroid(components.size(), Eigen::Vector3d::Zero());
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const int c = comp.vertex_component[static_cast<std::size_t>(v)];
    if (c >= 0) centroid[static_cast<std::size_t>(c)] += V.row(v).transpose();
  }
  for (std::size_t c = 0; c < components.size(); ++c) {
    centroid[c] /= static_cast<double>(components[c].vertex_count);
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const auto c = static_cast<std::size_t>(comp.face_component[static_cast<std::size_t>(f)]);
    const Eigen::Vector3d a = V.row(F(f, 0)).transpose() - centroid[c];
    const Eigen::Vector3d b = V.row(F(f, 1)).transpose() - centroid[c];
    const Eigen::Vector3d d = V.row(F(f, 2)).transpose() - centroid[c];
    components[c].signed_volume += a.dot(b.cross(d)) / 6.0;
  }
}

}  // namespace

OrientationReport orientation_report(PositionsRef V, FacesRef F) {
  validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), "orientation_report");
  const auto comp = detail::face_components(V.rows(), F);
  const auto inc = detail::vertex_face_incidence(V.rows(), F);
  const auto flags = edge_flags(V.rows(), F, inc);

  OrientationReport report;
  report.face_component = Eigen::Map<const Eigen::VectorXi>(comp.face_component.data(), F.rows());
  report.components.assign(static_cast<std::size_t>(comp.count), ComponentOrientation{});
  for (auto& c : report.components) c.closed = c.consistent = true;
  for (const int c : comp.face_component) {
    ++report.components[static_cast<std::size_t>(c)].face_count;
  }
  for (std::size_t v = 0; v < flags.size(); ++v) {
    const int c = comp.vertex_component[v];
    if (c < 0) continue;
    auto& component = report.components[static_cast<std::size_t>(c)];
    ++component.vertex_count;
    if (flags[v] & kOpenEdge) component.closed = false;
    if (flags[v] & kInconsistentEdge) component.consistent = false;
  }
  add_signed_volumes(V, F, comp, report.components);
  for (auto& c : report.components) c.inward = c.closed && c.consistent && c.signed_volume < 0.0;
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
FaceLinks face_links(std::int64_t vertex_count, FacesRef F, const detail::VertexFaces& inc) {
  FaceLinks links;
  links.across.assign(3 * static_cast<std::size_t>(F.rows()), -1);
  links.same.assign(3 * static_cast<std::size_t>(F.rows()), 0);
  detail::PerThread<std::vector<detail::EdgeSide>> scratch;
  detail::parallel_for(vertex_count, 0, [&](std::int64_t v) {
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

ConsistentFaces orient_consistently(int vertex_count, FacesRef F) {
  detail::check_face_indices(vertex_count, F, "orient_consistently");
  const auto inc = detail::vertex_face_incidence(vertex_count, F);
  const FaceLinks links = face_links(vertex_count, F, inc);
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

double fraction_against_faces(PositionsRef V, FacesRef F, NormalsRef N) {
  validate_mesh_arrays(V, F, N, "fraction_against_faces");
  if (N.rows() != V.rows()) {
    throw InvalidInput("fraction_against_faces: " + std::to_string(N.rows()) + " normals for " +
                       std::to_string(V.rows()) + " vertices");
  }
  // NaN rows (no face, or a vanishing sum) drop out through the finiteness test below.
  const RowMatrixX3d face_normals = vertex_normals(V, F, NormalWeighting::area);
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
