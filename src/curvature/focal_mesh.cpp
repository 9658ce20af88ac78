#include "focal/curvature/focal_mesh.h"

#include <cmath>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "mesh/prepared_access.h"

namespace focal {
namespace {

/// The focal points S - N / k of one principal curvature, clamped and flagged.
FocalMesh focal_points(PositionsRef V, const RowMatrixX3d& unit_normals,
                       const std::vector<char>& normal_ok, const Eigen::VectorXd& k,
                       double max_distance) {
  FocalMesh out;
  const Eigen::Index n = V.rows();
  out.mesh.V.resize(n, 3);
  out.flag.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!normal_ok[i] || !std::isfinite(k[i])) {
      out.mesh.V.row(i) = V.row(i);
      out.flag[i] = static_cast<std::uint8_t>(FocalPointFlag::undefined);
    } else if (std::abs(k[i]) * max_distance <= 1.0) {
      // Focal point at or beyond max_distance: clamp it, on the side it would lie on.
      const double side = k[i] > 0.0 ? -1.0 : 1.0;
      out.mesh.V.row(i) = V.row(i) + side * max_distance * unit_normals.row(i);
      out.flag[i] = static_cast<std::uint8_t>(FocalPointFlag::infinite);
    } else {
      out.mesh.V.row(i) = V.row(i) - unit_normals.row(i) / k[i];
      out.flag[i] = static_cast<std::uint8_t>(FocalPointFlag::finite);
    }
  }
  return out;
}

void keep_faces(FacesRef F, bool drop_at_infinity, FocalMesh& m) {
  std::vector<int> kept;
  kept.reserve(static_cast<std::size_t>(F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const bool finite = m.flag[F(f, 0)] == 0 && m.flag[F(f, 1)] == 0 && m.flag[F(f, 2)] == 0;
    if (finite || !drop_at_infinity) kept.push_back(static_cast<int>(f));
  }
  m.kept_faces =
      Eigen::Map<const Eigen::VectorXi>(kept.data(), static_cast<Eigen::Index>(kept.size()));
  m.mesh.F.resize(m.kept_faces.size(), 3);
  for (Eigen::Index t = 0; t < m.kept_faces.size(); ++t) m.mesh.F.row(t) = F.row(m.kept_faces[t]);
  m.mesh.face_source = m.kept_faces;
}

}  // namespace

FocalMeshes focal_meshes(const PreparedMesh& mesh, const CurvatureResult& curvature,
                         const FocalMeshOptions& options) {
  const PositionsRef& V = mesh.V();
  if (!mesh.has_normals() || curvature.k1.size() != V.rows() || curvature.k2.size() != V.rows()) {
    throw InvalidInput("focal meshes: " + std::to_string(V.rows()) + " vertices, but " +
                       (mesh.has_normals() ? "" : "no normals and ") +
                       std::to_string(curvature.k1.size()) + " curvature values");
  }
  if (!(options.max_distance >= 0.0)) throw InvalidInput("focal meshes: max_distance must be >= 0");
  const double max_distance =
      options.max_distance > 0.0 ? options.max_distance : 10.0 * bounding_box_diagonal(V);
  const detail::UnitNormals& unit = detail::unit_normals(mesh);
  FocalMeshes out{focal_points(V, unit.N, unit.ok, curvature.k1, max_distance),
                  focal_points(V, unit.N, unit.ok, curvature.k2, max_distance)};
  keep_faces(mesh.F(), options.drop_faces_at_infinity, out.gamma1);
  keep_faces(mesh.F(), options.drop_faces_at_infinity, out.gamma2);
  return out;
}

FocalMeshes focal_meshes(PositionsRef V, FacesRef F, NormalsRef N, const CurvatureResult& curvature,
                         const FocalMeshOptions& options) {
  return focal_meshes(detail::PreparedAccess::make(V, F, N, {}, "focal meshes"), curvature,
                      options);
}

}  // namespace focal
