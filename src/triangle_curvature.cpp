#include "focal/triangle_curvature.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "curvature_detail.h"
#include "focal/error.h"
#include "focal/normal_rays.h"
#include "normal_rays_detail.h"
#include "parallel.h"
#include "topology_incidence.h"

namespace focal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A result of m faces with the asked fields allocated but not written: each face's row is then
/// written once (values or NaN) by the thread that computes it, so nothing is filled twice and
/// the pages are first touched in parallel.
TriangleCurvatureResult unwritten_faces(Eigen::Index m, const TriangleFields& want) {
  TriangleCurvatureResult r;
  const auto scalars = [&](bool asked, std::initializer_list<Eigen::VectorXd*> fields) {
    for (Eigen::VectorXd* v : fields) v->resize(asked ? m : 0);
  };
  scalars(want.coefficients, {&r.A, &r.B, &r.C});
  scalars(want.curvatures, {&r.K, &r.H, &r.k1, &r.k2});
  scalars(want.focal_depths, {&r.lambda1, &r.lambda2});
  const auto vectors = [&](bool asked, std::initializer_list<RowMatrixX3d*> fields) {
    for (RowMatrixX3d* d : fields) d->resize(asked ? m : 0, 3);
  };
  vectors(want.directions, {&r.d1, &r.d2});
  vectors(want.slits, {&r.slit1, &r.slit2});
  vectors(want.face_normal, {&r.face_normal});
  r.shape_operator.resize(want.shape_operator ? m : 0, 4);
  r.point_class.resize(m);
  return r;
}

/// Face i `undefined`: NaN in every asked field.
void store_undefined_face(TriangleCurvatureResult& r, Eigen::Index i, const TriangleFields& want) {
  if (want.coefficients) r.A[i] = r.B[i] = r.C[i] = kNaN;
  if (want.curvatures) r.K[i] = r.H[i] = r.k1[i] = r.k2[i] = kNaN;
  if (want.focal_depths) r.lambda1[i] = r.lambda2[i] = kNaN;
  if (want.directions) r.d1.row(i).setConstant(kNaN), r.d2.row(i).setConstant(kNaN);
  if (want.slits) r.slit1.row(i).setConstant(kNaN), r.slit2.row(i).setConstant(kNaN);
  if (want.face_normal) r.face_normal.row(i).setConstant(kNaN);
  if (want.shape_operator) r.shape_operator.row(i).setConstant(kNaN);
  r.point_class[i] = static_cast<std::uint8_t>(PointClass::undefined);
}

/// The three vertex rays of a face in the frame of its mean normal, origin at its centroid.
struct FaceRays {
  TangentFrame frame;
  NormalRay r[3];
  Eigen::Vector2d offset[3];  ///< tangential position of each vertex relative to the centroid
};

// The inline bodies of tangent_frame and normal_ray (same formulas, no std::optional).
bool face_rays(PositionsRef V, const RowMatrixX3d& N, const std::vector<char>& ok,
               const Eigen::Vector3i& f, FaceRays& out) {
  if (!ok[f[0]] || !ok[f[1]] || !ok[f[2]]) return false;
  const Eigen::Vector3d sum = N.row(f[0]) + N.row(f[1]) + N.row(f[2]);
  const double len = sum.norm();
  if (!(len > 0.0) || !std::isfinite(len)) return false;
  out.frame = detail::frame_of(sum / len);
  const Eigen::Vector3d centroid = (V.row(f[0]) + V.row(f[1]) + V.row(f[2])).transpose() / 3.0;
  for (int c = 0; c < 3; ++c) {
    if (!detail::ray_of(out.frame, centroid, V.row(f[c]).transpose(), N.row(f[c]).transpose(),
                        out.r[c])) {
      return false;
    }
    out.offset[c] = out.frame.to_plane(V.row(f[c]).transpose() - centroid);
  }
  return true;
}

/// Unit slit direction at focal depth lambda from eq. 18, using whichever edge gives the longer
/// vector (Appendix B: the edge along which the two intersection points do not coincide).
/// Empty (zero) when both vanish, as at umbilics where all three rays meet in one point.
Eigen::Vector2d slit_direction(const Eigen::Matrix2d& X, const Eigen::Matrix2d& G, double lambda) {
  Eigen::Vector2d a = X.col(0) + lambda * G.col(0), b = X.col(1) + lambda * G.col(1);
  if (std::isinf(lambda)) a = G.col(0), b = G.col(1);  // limit of the direction as lambda -> inf
  const Eigen::Vector2d& longer = a.squaredNorm() >= b.squaredNorm() ? a : b;
  const double scale = X.norm() + (std::isinf(lambda) ? G.norm() : std::abs(lambda) * G.norm());
  return longer.norm() > 1e-9 * scale ? Eigen::Vector2d(longer.normalized())
                                      : Eigen::Vector2d::Zero();
}

/// Solves face i and writes its asked fields; false (nothing written) where it has no solution.
bool solve_face(const FaceRays& fr, Eigen::Index i, const detail::ClassTolerances& tol,
                const TriangleFields& want, TriangleCurvatureResult& r) {
  Eigen::Matrix2d X, G;  // columns: differences along the edges 0->1 and 0->2
  X << fr.r[1].u - fr.r[0].u, fr.r[2].u - fr.r[0].u, fr.r[1].v - fr.r[0].v, fr.r[2].v - fr.r[0].v;
  G << fr.r[1].sigma - fr.r[0].sigma, fr.r[2].sigma - fr.r[0].sigma, fr.r[1].tau - fr.r[0].tau,
      fr.r[2].tau - fr.r[0].tau;
  if (!(std::abs(X.determinant()) > 1e-14 * X.squaredNorm()))
    return false;  // no area in the ray frame
  // The centroid lies below the surface by the sagitta s = (1/6) sum x_i^T M x_i (second order,
  // x_i the vertices' tangential offsets). Depths measured from the centroid's plane would
  // carry that O(h^2) bias into K and H, so the rays are re-parametrised on the plane z = s,
  // the tangent plane at the surface point above the centroid: (u, v) += s (sigma, tau).
  const Eigen::Matrix2d M0 = G * X.inverse();
  const Eigen::Matrix2d S0 = 0.5 * (M0 + M0.transpose());
  double sagitta = 0.0;
  for (const Eigen::Vector2d& x : fr.offset) sagitta += x.dot(S0 * x);
  sagitta /= 6.0;
  X += sagitta * G;
  const double A = G.determinant();
  const double B = G(0, 0) * X(1, 1) - G(0, 1) * X(1, 0) - G(1, 0) * X(0, 1) + G(1, 1) * X(0, 0);
  const double C = X.determinant();
  if (!(std::abs(C) > 1e-14 * X.squaredNorm())) return false;
  const double K = A / C, H = B / (2.0 * C);
  // H^2 < K only through rounding or a non-symmetric M (noise): treat as the double root H.
  const double root = std::sqrt(std::max(H * H - K, 0.0));
  const double k1 = H + root, k2 = H - root;
  if (want.coefficients) r.A[i] = A, r.B[i] = B, r.C[i] = C;
  if (want.curvatures) r.K[i] = K, r.H[i] = H, r.k1[i] = k1, r.k2[i] = k2;
  const double lambda1 = -1.0 / k1, lambda2 = -1.0 / k2;
  if (want.focal_depths) r.lambda1[i] = lambda1, r.lambda2[i] = lambda2;
  // M again on the shifted X, only where an asked field needs it (two divisions saved).
  const bool need_operator = want.directions || want.slits || want.shape_operator;
  const Eigen::Matrix2d M = need_operator ? Eigen::Matrix2d(G * X.inverse()) : Eigen::Matrix2d();
  if (want.directions || want.slits) {
    const detail::Principal2 p =
        detail::principal_from_symmetric(M(0, 0), 0.5 * (M(0, 1) + M(1, 0)), M(1, 1));
    if (want.directions) {
      r.d1.row(i) = fr.frame.from_plane(p.d1);
      r.d2.row(i) = fr.frame.from_plane(p.d2);
    }
    if (want.slits) {
      // Where eq. 18 is degenerate (umbilic) the slits are the principal lines: slit1 along d2.
      const Eigen::Vector2d s1 = slit_direction(X, G, lambda1), s2 = slit_direction(X, G, lambda2);
      r.slit1.row(i) = fr.frame.from_plane(s1.squaredNorm() > 0 ? s1 : p.d2);
      r.slit2.row(i) = fr.frame.from_plane(s2.squaredNorm() > 0 ? s2 : p.d1);
    }
  }
  if (want.face_normal) r.face_normal.row(i) = fr.frame.n;
  if (want.shape_operator) r.shape_operator.row(i) << M(0, 0), M(0, 1), M(1, 0), M(1, 1);
  r.point_class[i] = static_cast<std::uint8_t>(classify(k1, k2, tol.zero, tol.umbilic));
  return true;
}

/// The minimal rotation taking unit a to unit b applied to w (Rodrigues; a.b > -1 holds since
/// both normals lie in each other's hemisphere here).
Eigen::Vector3d rotate_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                               const Eigen::Vector3d& w) {
  const Eigen::Vector3d axis = a.cross(b);
  const double c = a.dot(b);
  return w + axis.cross(w) + axis.cross(axis.cross(w)) / (1.0 + c);
}

/// The face's symmetrised shape operator in a vertex's tangent frame: the face frame is rotated
/// onto the vertex's tangent plane (a rotation, not a projection, so that a face operator kI
/// stays kI exactly, as on a sphere).
Eigen::Matrix2d operator_in_frame(const TriangleCurvatureResult& t, int f, const TangentFrame& to) {
  const TangentFrame from = detail::frame_of(t.face_normal.row(f).transpose());
  const auto& m = t.shape_operator.row(f);
  Eigen::Matrix2d sym;
  sym << m[0], 0.5 * (m[1] + m[2]), 0.5 * (m[1] + m[2]), m[3];
  const Eigen::Vector3d x = rotate_between(from.n, to.n, from.x);
  const Eigen::Vector3d y = rotate_between(from.n, to.n, from.y);
  Eigen::Matrix2d q;  // orthogonal change of basis from the rotated face axes to (to.x, to.y)
  q << to.x.dot(x), to.x.dot(y), to.y.dot(x), to.y.dot(y);
  return q * sym * q.transpose();
}

double face_area(PositionsRef V, FacesRef F, int f) {
  const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
  return 0.5 * (b - a).cross(c - a).norm();
}

}  // namespace

TriangleCurvatureResult triangle_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options) {
  return triangle_curvature(V, F, N, options, TriangleFields{});
}

TriangleCurvatureResult triangle_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options,
                                           const TriangleFields& fields) {
  if (N.rows() != V.rows()) {
    throw InvalidInput("triangle curvature: " + std::to_string(N.rows()) + " normals for " +
                       std::to_string(V.rows()) + " vertices");
  }
  validate_mesh_arrays(V, F, N, "triangle curvature");
  std::vector<char> ok;
  const RowMatrixX3d unit = detail::unit_rows(N, ok, options.threads);
  const detail::ClassTolerances tol = detail::class_tolerances(options, mean_edge_length(V, F));
  TriangleCurvatureResult r = unwritten_faces(F.rows(), fields);
  detail::parallel_for(F.rows(), options.threads, [&](std::int64_t f) {
    FaceRays fr;
    if (!face_rays(V, unit, ok, F.row(f).transpose(), fr) || !solve_face(fr, f, tol, fields, r)) {
      store_undefined_face(r, f, fields);
    }
  });
  return r;
}

namespace {

/// One face's part of a vertex's mean operator.
struct FacePart {
  double area;
  Eigen::Matrix2d op;
};

/// Area-weighted mean of the operators of vertex i's usable faces, and their spread about it.
void average_at_vertex(PositionsRef V, FacesRef F, const TriangleCurvatureResult& faces,
                       const detail::VertexFaces& inc, const RowMatrixX3d& unit,
                       const detail::ClassTolerances& tol, Eigen::Index i,
                       std::vector<FacePart>& parts, CurvatureResult& r) {
  const TangentFrame frame = detail::frame_of(unit.row(i).transpose());
  parts.clear();
  Eigen::Matrix2d mean = Eigen::Matrix2d::Zero();
  double area = 0.0;
  for (int k = inc.begin(i); k < inc.end(i); ++k) {
    const int f = inc.faces[static_cast<std::size_t>(k)];
    if (faces.point_class[f] == static_cast<std::uint8_t>(PointClass::undefined) ||
        !(faces.face_normal.row(f).dot(frame.n) > 0.0)) {
      continue;
    }
    parts.push_back({face_area(V, F, f), operator_in_frame(faces, f, frame)});
    mean += parts.back().area * parts.back().op;
    area += parts.back().area;
  }
  r.rays_used[i] = static_cast<int>(parts.size());
  r.rays_excluded[i] = inc.size(i) - r.rays_used[i];
  if (!(area > 0.0)) return detail::store_undefined(r, i);
  mean /= area;
  double spread = 0.0;
  for (const auto& [a, m] : parts) spread += a * (m - mean).squaredNorm();
  const auto p =
      detail::principal_from_symmetric(mean(0, 0), 0.5 * (mean(0, 1) + mean(1, 0)), mean(1, 1));
  detail::store_vertex(r, i, frame, p, std::sqrt(spread / area), tol);
}

}  // namespace

CurvatureResult vertex_curvature_from_triangles(PositionsRef V, FacesRef F, NormalsRef N,
                                                const CurvatureOptions& options) {
  // Only what the averaging reads: the face operators, their normals and classes.
  TriangleFields needed;
  needed.coefficients = needed.curvatures = needed.focal_depths = false;
  needed.directions = needed.slits = false;
  const TriangleCurvatureResult faces = triangle_curvature(V, F, N, options, needed);
  std::vector<char> ok;
  const RowMatrixX3d unit = detail::unit_rows(N, ok, options.threads);
  const detail::VertexFaces inc = detail::vertex_face_incidence(V.rows(), F);
  const detail::ClassTolerances tol = detail::class_tolerances(options, mean_edge_length(V, F));
  CurvatureResult r = detail::unwritten_result(V.rows());
  // Scratch per block of vertices, as in the per-vertex fit: no allocation per vertex.
  detail::parallel_for_blocks(V.rows(), 256, options.threads,
                              [&](std::int64_t begin, std::int64_t end) {
                                std::vector<FacePart> parts;
                                for (auto i = begin; i < end; ++i) {
                                  if (ok[static_cast<std::size_t>(i)]) {
                                    average_at_vertex(V, F, faces, inc, unit, tol, i, parts, r);
                                  } else {
                                    detail::store_undefined(r, i);
                                    r.rays_used[i] = r.rays_excluded[i] = 0;
                                  }
                                }
                              });
  return r;
}

}  // namespace focal
