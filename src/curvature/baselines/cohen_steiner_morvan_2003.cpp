// CSM03: Cohen-Steiner and Morvan (2003), the normal-cycle curvature tensor; the paper's second
// baseline.
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "curvature/vertex_rows.h"
#include "focal/core/error.h"
#include "focal/curvature/baselines.h"
#include "focal/mesh/neighbourhood.h"
#include "mesh/prepared_access.h"
#include "mesh/topology.h"

namespace focal::baselines {
namespace {

/// The undirected edges of the mesh with beta(e) |e| e e^T, and the three edges of each face.
struct EdgeTensors {
  std::vector<Eigen::Matrix3d> tensor;         ///< per edge; zero on boundary/non-manifold edges
  std::vector<std::array<int, 3>> face_edges;  ///< per face
};

/// Signed dihedral angle at the edge (a, b) between faces with unit normals n1 (the face
/// containing `opposite1`) and n2: positive where the surface is convex (outward normals).
double signed_dihedral(const Eigen::Vector3d& n1, const Eigen::Vector3d& n2,
                       const Eigen::Vector3d& a, const Eigen::Vector3d& opposite2) {
  const double angle = std::atan2(n1.cross(n2).norm(), n1.dot(n2));
  return (opposite2 - a).dot(n1) < 0.0 ? angle : -angle;
}

EdgeTensors edge_tensors(PositionsRef V, FacesRef F) {
  struct HalfEdge {
    std::int64_t key;
    int face, corner;
  };
  const std::int64_t n = V.rows();
  std::vector<HalfEdge> half(static_cast<std::size_t>(3 * F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const std::int64_t a = F(f, c), b = F(f, (c + 1) % 3);
      half[3 * f + c] = {std::min(a, b) * n + std::max(a, b), static_cast<int>(f), c};
    }
  }
  std::sort(half.begin(), half.end(), [](auto& x, auto& y) { return x.key < y.key; });
  EdgeTensors out;
  out.face_edges.resize(static_cast<std::size_t>(F.rows()));
  for (std::size_t e = 0; e < half.size();) {
    std::size_t end = e;
    while (end < half.size() && half[end].key == half[e].key) ++end;
    const int id = static_cast<int>(out.tensor.size());
    Eigen::Matrix3d t = Eigen::Matrix3d::Zero();
    if (end - e == 2) {  // beta is defined on edges with exactly two faces
      const HalfEdge &h1 = half[e], &h2 = half[e + 1];
      const Eigen::Vector3d a = V.row(F(h1.face, h1.corner)),
                            b = V.row(F(h1.face, (h1.corner + 1) % 3));
      const auto unit_normal = [&](int f) {
        const Eigen::Vector3d p = V.row(F(f, 0)), q = V.row(F(f, 1)), r = V.row(F(f, 2));
        return Eigen::Vector3d((q - p).cross(r - p).normalized());
      };
      const Eigen::Vector3d opposite2 = V.row(F(h2.face, (h2.corner + 2) % 3));
      const double beta = signed_dihedral(unit_normal(h1.face), unit_normal(h2.face), a, opposite2);
      const Eigen::Vector3d edge = b - a;
      if (std::isfinite(beta) && edge.norm() > 0.0)
        t = beta / edge.norm() * edge * edge.transpose();
    }
    for (std::size_t k = e; k < end; ++k) out.face_edges[half[k].face][half[k].corner] = id;
    out.tensor.push_back(t);
    e = end;
  }
  return out;
}

double triangle_area(PositionsRef V, FacesRef F, int f) {
  const Eigen::Vector3d p = V.row(F(f, 0)), q = V.row(F(f, 1)), r = V.row(F(f, 2));
  return 0.5 * (q - p).cross(r - p).norm();
}

/// The faces of the neighbourhood B of vertex i: incident to i or to a vertex of its
/// (rings - 1)-ring, each once, in increasing order.
void neighbourhood_faces(const detail::VertexFaces& inc, const Neighbourhoods& centres, int rings,
                         int i, std::vector<int>& faces) {
  faces.assign(inc.faces.begin() + inc.begin(i), inc.faces.begin() + inc.end(i));
  if (rings == 1) return;
  for (const int* c = centres.begin(i); c != centres.end(i); ++c) {
    faces.insert(faces.end(), inc.faces.begin() + inc.begin(*c), inc.faces.begin() + inc.end(*c));
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
}

}  // namespace

CurvatureResult cohen_steiner_morvan_2003(PositionsRef V, FacesRef F,
                                          const CurvatureOptions& options) {
  if (options.rings < 1)
    throw InvalidInput("CSM03: rings must be >= 1, got " + std::to_string(options.rings));
  const PreparedMesh mesh = detail::PreparedAccess::make(V, F, std::nullopt, {}, "CSM03");
  const EdgeTensors edges = edge_tensors(V, F);
  const std::shared_ptr<const detail::VertexFaces> incidence = detail::incidence(mesh);
  const detail::VertexFaces& inc = *incidence;
  const Neighbourhoods centres =
      options.rings > 1 ? k_ring(*detail::one_ring(mesh), options.rings - 1) : Neighbourhoods{};
  const detail::ClassTolerances tol = detail::class_tolerances(options, mesh.mean_edge_length());
  CurvatureResult r = detail::undefined_result(V.rows(), 0);
  detail::parallel_for(V.rows(), 0, [&](std::int64_t i) {
    thread_local std::vector<int> faces;
    neighbourhood_faces(inc, centres, options.rings, static_cast<int>(i), faces);
    Eigen::Matrix3d T = Eigen::Matrix3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    double area = 0.0;
    for (int f : faces) {
      area += triangle_area(V, F, f);
      const Eigen::Vector3d p = V.row(F(f, 0)), q = V.row(F(f, 1)), w = V.row(F(f, 2));
      if (F(f, 0) == i || F(f, 1) == i || F(f, 2) == i) normal += (q - p).cross(w - p);
      // |e n B| / |e|: an edge between two faces of B is reached twice, an edge on the border
      // of B once, so half of its tensor per face counts it fully or by half.
      for (int e : edges.face_edges[f]) T += 0.5 * edges.tensor[e];
    }
    if (!(area > 0.0) || !(normal.norm() > 0.0)) return;
    const TangentFrame frame = tangent_frame(normal.normalized());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(T / area);
    int drop = 0;  // the eigenvector closest to the normal
    for (int k = 1; k < 3; ++k) {
      if (std::abs(eig.eigenvectors().col(k).dot(frame.n)) >
          std::abs(eig.eigenvectors().col(drop).dot(frame.n)))
        drop = k;
    }
    const int a = drop == 0 ? 1 : 0, b = drop == 2 ? 1 : 2;
    // The curvature eigenvalue of one tangent eigenvector belongs to the other direction.
    const int larger = eig.eigenvalues()[a] >= eig.eigenvalues()[b] ? a : b,
              smaller = a + b - larger;
    detail::Principal2 p;
    p.k1 = eig.eigenvalues()[larger];
    p.k2 = eig.eigenvalues()[smaller];
    p.d1 = frame.to_plane(eig.eigenvectors().col(smaller)).normalized();
    p.d2 = Eigen::Vector2d(-p.d1.y(), p.d1.x());
    detail::store_vertex(r, i, frame, p, std::abs(eig.eigenvalues()[drop]), tol);
    r.rays_used[i] = static_cast<int>(faces.size());  // faces in the neighbourhood
  });
  return r;
}

}  // namespace focal::baselines
