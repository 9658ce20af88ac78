// GGRZ06: the mid-edge shape operator (Grinspun, Gingold, Reisman, Zorin, Eurographics 2006).
//
// The normals are interpolated linearly over a face from their values n_j at the edge
// midpoints (the non-conforming linear element whose basis function of edge j is 1 - 2 lambda_j,
// lambda_j the barycentric coordinate of the opposite corner). Its gradient is
// dn = -(1 / A) sum_j n_j (N x e_j)^T = (1 / A) sum_j |e_j| n_j t_j^T with e_j the edge opposite
// corner j (counter-clockwise) and t_j = e_j x N / |e_j|. The paper keeps the component of n_j
// along t_j (the bending across the edge), giving the symmetric
// S = (1 / A) sum_j |e_j| <n_j, t_j> t_j t_j^T; with n_j the normalised mean of the two face
// normals, <n_j, t_j> = sin(theta_j / 2), theta_j the signed dihedral angle (positive on convex
// edges, so a sphere of radius R gets S = I / R on equilateral faces: focal's sign).
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "core/parallel.h"
#include "curvature/vertex_rows.h"
#include "focal/curvature/baselines.h"
#include "mesh/prepared_access.h"
#include "mesh/topology.h"

namespace focal::baselines {
namespace {

struct FaceFrame {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit; zero on a degenerate face
  double area = 0.0;
};

FaceFrame face_frame(PositionsRef V, FacesRef F, std::int64_t f) {
  const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
  const Eigen::Vector3d cross = (b - a).cross(c - a);
  if (focal::detail::is_degenerate_triangle(a, b, c) || !cross.allFinite()) return {};
  return {cross.normalized(), 0.5 * cross.norm()};
}

/// The face across the edge (a, b) of face f: the one other face holding both, or -1 on a
/// boundary or non-manifold edge.
int face_across(FacesRef F, const focal::detail::VertexFaces& inc, int f, int a, int b) {
  int found = -1;
  for (int k = inc.begin(a); k < inc.end(a); ++k) {
    const int g = inc.faces[k];
    if (g == f || (F(g, 0) != b && F(g, 1) != b && F(g, 2) != b)) continue;
    if (found >= 0) return -1;
    found = g;
  }
  return found;
}

/// The face's shape operator (3 x 3, in its plane).
Eigen::Matrix3d face_operator(PositionsRef V, FacesRef F, const focal::detail::VertexFaces& inc,
                              const std::vector<FaceFrame>& frames, int f) {
  const FaceFrame& own = frames[static_cast<std::size_t>(f)];
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (int j = 0; j < 3; ++j) {
    const int a = F(f, (j + 1) % 3), b = F(f, (j + 2) % 3);
    const Eigen::Vector3d e = V.row(b) - V.row(a);
    const Eigen::Vector3d t = e.cross(own.normal).normalized();
    const int g = face_across(F, inc, f, a, b);
    const Eigen::Vector3d other = g >= 0 ? frames[static_cast<std::size_t>(g)].normal : own.normal;
    const Eigen::Vector3d mid = own.normal + other;  // zero only on a folded edge
    if (!(mid.norm() > 0.0)) continue;
    S += e.norm() * mid.normalized().dot(t) * t * t.transpose();
  }
  return S / own.area;
}

}  // namespace

CurvatureResult grinspun_2006(PositionsRef V, FacesRef F, const CurvatureOptions& options) {
  const PreparedMesh mesh = focal::detail::PreparedAccess::make(V, F, std::nullopt, {}, "GGRZ06");
  const auto incidence = focal::detail::incidence(mesh);
  const focal::detail::VertexFaces& inc = *incidence;
  std::vector<FaceFrame> frames(static_cast<std::size_t>(F.rows()));
  focal::detail::parallel_for(F.rows(), 0, [&](std::int64_t f) {
    frames[static_cast<std::size_t>(f)] = face_frame(V, F, f);
  });
  std::vector<Eigen::Matrix3d> face_S(static_cast<std::size_t>(F.rows()));
  focal::detail::parallel_for(F.rows(), 0, [&](std::int64_t f) {
    face_S[static_cast<std::size_t>(f)] =
        frames[static_cast<std::size_t>(f)].area > 0.0
            ? face_operator(V, F, inc, frames, static_cast<int>(f))
            : Eigen::Matrix3d::Zero();
  });
  const focal::detail::ClassTolerances tol =
      focal::detail::class_tolerances(options, mesh.mean_edge_length());
  CurvatureResult result = focal::detail::undefined_result(V.rows(), 0);
  focal::detail::parallel_for(V.rows(), 0, [&](std::int64_t i) {
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    double area = 0.0;
    for (int k = inc.begin(i); k < inc.end(i); ++k) {
      const FaceFrame& face = frames[static_cast<std::size_t>(inc.faces[k])];
      normal += face.area * face.normal;
      area += face.area;
    }
    if (!(area > 0.0) || !(normal.norm() > 0.0)) return;
    normal.normalize();
    Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
    for (int k = inc.begin(i); k < inc.end(i); ++k) {
      const int f = inc.faces[k];
      const FaceFrame& face = frames[static_cast<std::size_t>(f)];
      if (!(face.area > 0.0)) continue;
      const Eigen::Matrix3d R =
          Eigen::Quaterniond::FromTwoVectors(face.normal, normal).toRotationMatrix();
      S += face.area * R * face_S[static_cast<std::size_t>(f)] * R.transpose();
    }
    S /= area;
    const TangentFrame frame = tangent_frame(normal);
    const Eigen::Vector2d x = frame.to_plane(S * frame.x), y = frame.to_plane(S * frame.y);
    const focal::detail::Principal2 p =
        focal::detail::principal_from_symmetric(x.x(), 0.5 * (x.y() + y.x()), y.y());
    // Residual: the operator's normal component left after rotating the faces' operators.
    focal::detail::store_vertex(result, i, frame, p, (S * normal).norm(), tol);
    result.rays_used[i] = inc.size(i);  // faces averaged
  });
  return result;
}

}  // namespace focal::baselines
