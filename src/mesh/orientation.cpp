#include "focal/mesh/orientation.h"

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "kernels/vec3.h"
#include "mesh/orientation_detail.h"
#include "mesh/prepared_access.h"
#include "mesh/statistics_detail.h"
#include "mesh/topology.h"

namespace focal {
namespace {

using Vec3 = kernels::Vec3<double>;
using kernels::cross;
using kernels::dot;

inline Vec3 row(PositionsRef V, Eigen::Index i) { return {V(i, 0), V(i, 1), V(i, 2)}; }

}  // namespace

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

OrientationReport orientation_report(PositionsRef V, FacesRef F) {
  return orientation_report(
      detail::PreparedAccess::make(V, F, std::nullopt, {}, "orientation_report"));
}

OrientationReport orientation_report(const PreparedMesh& mesh) {
  return detail::orientation_report_from(
      mesh.V(), mesh.F(),
      detail::mesh_topology(*detail::incidence(mesh), mesh.F(), detail::TopologyDetail::orientation,
                            0),
      0);
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

ConsistentFaces orient_consistently(int vertex_count, FacesRef F) {
  detail::check_face_indices(vertex_count, F, "orient_consistently");
  const auto inc = detail::vertex_face_incidence(vertex_count, F, 0);
  const FaceLinks links = face_links(vertex_count, F, inc, 0);
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

}  // namespace focal
