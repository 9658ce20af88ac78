#include "focal/mesh/check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/orientation.h"
#include "focal/normals/vertex_normals.h"
#include "mesh/orientation_detail.h"
#include "mesh/prepared_access.h"
#include "mesh/statistics_detail.h"
#include "mesh/topology.h"
#include "normals/vertex_normals_from.h"

namespace focal {
namespace {

/// Tolerance on |n| - 1 below which a given normal counts as unit (the estimator's, curvature.h).
constexpr double kUnitTolerance = 1e-6;

/// Sums count(i) over [0, n) in parallel blocks (integers: exact for any split).
template <class Count>
int parallel_count(std::int64_t n, int threads, Count&& count) {
  constexpr std::int64_t kBlock = 1 << 14;
  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<int> sums(static_cast<std::size_t>(blocks), 0);
  detail::parallel_blocks(n, kBlock, threads,
                          [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
                            int sum = 0;
                            for (auto i = begin; i < end; ++i) sum += count(i);
                            sums[static_cast<std::size_t>(b)] = sum;
                          });
  int total = 0;
  for (const int sum : sums) total += sum;
  return total;
}

/// Sums add(sum, i) over [0, n) in parallel blocks, then the blocks in order (for integer
/// tallies: exact for any split).
template <class Sum, class Add>
Sum parallel_sum(std::int64_t n, int threads, Add&& add) {
  constexpr std::int64_t kBlock = 1 << 14;
  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<Sum> sums(static_cast<std::size_t>(blocks));
  detail::parallel_blocks(n, kBlock, threads,
                          [&](std::int64_t b, std::int64_t begin, std::int64_t end) {
                            Sum sum{};
                            for (auto i = begin; i < end; ++i) add(sum, i);
                            sums[static_cast<std::size_t>(b)] = sum;
                          });
  Sum total{};
  for (const Sum& sum : sums) total += sum;
  return total;
}

/// The findings about given normals: their rows, and their direction against the faces.
void check_normals(PositionsRef V, FacesRef F, NormalsRef N, const detail::VertexFaces& incidence,
                   const detail::MeshTopology& topology, const OrientationReport& report,
                   int threads, MeshFindings& out) {
  // One pass over the rows for the three row findings (integer counts: exact for any split).
  struct RowCounts {
    int non_finite = 0, zero = 0, non_unit = 0;
    RowCounts& operator+=(const RowCounts& o) {
      non_finite += o.non_finite, zero += o.zero, non_unit += o.non_unit;
      return *this;
    }
  };
  const RowCounts rows =
      parallel_sum<RowCounts>(N.rows(), threads, [&](RowCounts& c, std::int64_t i) {
        if (!N.row(i).allFinite()) {
          ++c.non_finite;
          return;
        }
        const double length = N.row(i).norm();
        c.zero += length == 0.0 ? 1 : 0;
        c.non_unit += length != 0.0 && std::abs(length - 1.0) > kUnitTolerance ? 1 : 0;
      });
  out.non_finite_normal_count = rows.non_finite;
  out.zero_normal_count = rows.zero;
  out.non_unit_normal_count = rows.non_unit;
  // Area weights: the face normals' own average, NaN where it does not exist (no usable face).
  const RowMatrixX3d from_faces =
      detail::vertex_normals_from(V, F, incidence, NormalWeighting::area, threads);
  const auto& component = topology.components.vertex_component;
  struct Tally {  // vertices with both normals, those against the faces, those pointing inside
    int compared = 0, against = 0, inside = 0, judged = 0;
    Tally& operator+=(const Tally& o) {
      compared += o.compared, against += o.against, inside += o.inside, judged += o.judged;
      return *this;
    }
  };
  // Keyed by component; vertices in no face have no face normal and drop out with it.
  std::vector<Tally> tally(report.components.size());
  detail::add_by_key_runs(
      N.rows(), threads, [&](std::int64_t i) { return component[static_cast<std::size_t>(i)]; },
      [&](Tally& t, std::int64_t i) {
        const double dot = N.row(i).dot(from_faces.row(i));
        if (!std::isfinite(dot)) return;
        ++t.compared;
        t.against += dot < 0.0 ? 1 : 0;
        const auto& info =
            report.components[static_cast<std::size_t>(component[static_cast<std::size_t>(i)])];
        if (!info.closed || !info.consistent || !std::isfinite(info.signed_volume)) return;
        // The faces of an inward component point inside, so a normal with them points inside.
        const bool inside = info.signed_volume < 0.0 ? dot > 0.0 : dot < 0.0;
        t.inside += inside ? 1 : 0;
        ++t.judged;
      },
      tally);
  for (const Tally& t : tally) {
    out.normals_compared_count += t.compared;
    out.normals_against_faces_count += t.against;
    out.inward_normal_component_count += 2 * t.inside > t.judged ? 1 : 0;
  }
}

/// check_mesh's counts, computed.
MeshFindings find_problems(const PreparedMesh& mesh) {
  const PositionsRef& V = mesh.V();
  const FacesRef& F = mesh.F();
  const std::shared_ptr<const detail::VertexFaces> incidence = detail::incidence(mesh);
  // One topology pass serves the statistics and the orientation report (each computed its own).
  // It also builds the 1-ring from its sorted edge sides, which the estimators ask for next:
  // kept on the mesh, it is not built a second time.
  Neighbourhoods one_ring;
  const detail::MeshTopology topology =
      detail::mesh_topology(*incidence, F, detail::TopologyDetail::statistics, 0, &one_ring);
  detail::PreparedAccess::offer_one_ring(mesh, std::move(one_ring));
  const OrientationReport report = detail::orientation_report_from(V, F, topology, 0);
  MeshFindings out;
  out.non_finite_vertex_count =
      parallel_count(V.rows(), 0, [&](std::int64_t i) { return !V.row(i).allFinite(); });
  // Both in one pass over the faces.
  const detail::DegenerateFaces degenerate = detail::degenerate_faces(V, F, 0);
  out.repeated_index_face_count = static_cast<int>(degenerate.repeated_index);
  out.degenerate_face_count = static_cast<int>(degenerate.zero_area);
  out.duplicate_face_count = static_cast<int>(topology.duplicate_face_count);
  out.unreferenced_vertex_count = static_cast<int>(topology.unreferenced_vertex_count);
  out.non_manifold_edge_count = static_cast<int>(topology.non_manifold_edge_count);
  out.non_manifold_vertex_count = static_cast<int>(topology.non_manifold_vertex_count);
  for (const auto& c : report.components) out.inconsistent_component_count += c.consistent ? 0 : 1;
  out.inward_component_count = report.inward_count();
  out.boundary_edge_count = static_cast<int>(topology.boundary_edge_count);
  out.component_count = topology.components.count;
  if (mesh.has_normals()) {
    check_normals(V, F, mesh.N(), *incidence, topology, report, 0, out);
  }
  return out;
}

void append(std::string& text, int count, const char* singular, const char* plural) {
  if (count == 0) return;
  if (!text.empty()) text += ", ";
  text += std::to_string(count) + " " + (count == 1 ? singular : plural);
}

}  // namespace

bool MeshFindings::has_problems() const { return !summary().empty(); }

std::string MeshFindings::summary() const {
  std::string s;
  append(s, non_finite_vertex_count, "non-finite vertex", "non-finite vertices");
  append(s, repeated_index_face_count, "face with a repeated vertex",
         "faces with a repeated vertex");
  append(s, degenerate_face_count, "zero-area face", "zero-area faces");
  append(s, duplicate_face_count, "duplicate face", "duplicate faces");
  append(s, unreferenced_vertex_count, "unreferenced vertex", "unreferenced vertices");
  append(s, non_manifold_edge_count, "non-manifold edge", "non-manifold edges");
  append(s, non_manifold_vertex_count, "non-manifold vertex", "non-manifold vertices");
  append(s, inconsistent_component_count, "inconsistently oriented component",
         "inconsistently oriented components");
  append(s, inward_component_count, "inward-oriented component", "inward-oriented components");
  append(s, non_finite_normal_count, "non-finite normal", "non-finite normals");
  append(s, zero_normal_count, "zero normal", "zero normals");
  append(s, non_unit_normal_count, "non-unit normal", "non-unit normals");
  append(s, normals_against_faces_count, "normal against its faces", "normals against their faces");
  append(s, inward_normal_component_count, "component with inward normals",
         "components with inward normals");
  return s;
}

MeshFindings check_mesh(PositionsRef V, FacesRef F, std::optional<NormalsRef> N) {
  return check_mesh(detail::PreparedAccess::make(V, F, N, {}, "check_mesh"));
}

MeshFindings check_mesh(const PreparedMesh& mesh) {
  return detail::PreparedAccess::findings(mesh, [&] { return find_problems(mesh); });
}

}  // namespace focal
