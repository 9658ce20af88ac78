#include "focal/mesh_check.h"

#include <cmath>
#include <cstddef>
#include <vector>

#include "focal/neighbourhood.h"
#include "focal/normals.h"
#include "topology_incidence.h"

namespace focal {
namespace {

/// Tolerance on |n| - 1 below which a given normal counts as unit (the estimator's, curvature.h).
constexpr double kUnitTolerance = 1e-6;

int count_non_finite_rows(const Eigen::Ref<const RowMatrixX3d>& M) {
  int count = 0;
  for (Eigen::Index i = 0; i < M.rows(); ++i) count += M.row(i).allFinite() ? 0 : 1;
  return count;
}

int count_repeated_index_faces(FacesRef F) {
  int count = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) count += detail::has_repeated_index(F, f) ? 1 : 0;
  return count;
}

/// Component of each vertex (that of its lowest-index face), -1 for vertices in no face.
std::vector<int> vertex_components(Eigen::Index vertex_count, FacesRef F,
                                   const OrientationReport& report) {
  std::vector<int> component(static_cast<std::size_t>(vertex_count), -1);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      int& slot = component[static_cast<std::size_t>(F(f, c))];
      if (slot < 0) slot = report.face_component[f];
    }
  }
  return component;
}

/// The findings about given normals: their rows, and their direction against the faces.
void check_normals(PositionsRef V, FacesRef F, NormalsRef N, const OrientationReport& report,
                   MeshFindings& out) {
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const double length = N.row(i).norm();
    if (!N.row(i).allFinite()) {
      ++out.non_finite_normal_count;
    } else if (length == 0.0) {
      ++out.zero_normal_count;
    } else if (std::abs(length - 1.0) > kUnitTolerance) {
      ++out.non_unit_normal_count;
    }
  }
  // Area weights: the face normals' own average, NaN where it does not exist (no usable face).
  const RowMatrixX3d from_faces = vertex_normals(V, F, NormalWeighting::area);
  const std::vector<int> component = vertex_components(V.rows(), F, report);
  std::vector<int> inward(report.components.size(), 0), counted(report.components.size(), 0);
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const double dot = N.row(i).dot(from_faces.row(i));
    if (!std::isfinite(dot)) continue;
    out.normals_against_faces_count += dot < 0.0 ? 1 : 0;
    const int c = component[static_cast<std::size_t>(i)];
    const auto& info = report.components[static_cast<std::size_t>(c)];
    if (!info.closed || !info.consistent || !std::isfinite(info.signed_volume)) continue;
    // The faces of an inward component point inside, so a normal with them points inside too.
    const bool inside = info.signed_volume < 0.0 ? dot > 0.0 : dot < 0.0;
    inward[static_cast<std::size_t>(c)] += inside ? 1 : 0;
    ++counted[static_cast<std::size_t>(c)];
  }
  for (std::size_t c = 0; c < inward.size(); ++c) {
    out.inward_normal_component_count += 2 * inward[c] > counted[c] ? 1 : 0;
  }
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

MeshFindings check_mesh(PositionsRef V, FacesRef F, NormalsRef N) {
  validate_mesh_arrays(V, F, N, "check_mesh");
  const MeshStatistics stats = mesh_statistics(V, F);
  const OrientationReport report = orientation_report(V, F);
  MeshFindings out;
  out.non_finite_vertex_count = count_non_finite_rows(V);
  out.repeated_index_face_count = count_repeated_index_faces(F);
  // mesh_statistics counts faces with a repeated index as degenerate too.
  out.degenerate_face_count = stats.degenerate_face_count - out.repeated_index_face_count;
  out.duplicate_face_count = stats.duplicate_face_count;
  out.unreferenced_vertex_count = stats.unreferenced_vertex_count;
  out.non_manifold_edge_count = stats.non_manifold_edge_count;
  out.non_manifold_vertex_count = stats.non_manifold_vertex_count;
  for (const auto& c : report.components) out.inconsistent_component_count += c.consistent ? 0 : 1;
  out.inward_component_count = report.inward_count();
  out.boundary_edge_count = stats.boundary_edge_count;
  out.component_count = stats.component_count;
  if (N.rows() > 0) check_normals(V, F, N, report, out);
  return out;
}

}  // namespace focal
