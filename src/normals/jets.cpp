#include "focal/normals/jets.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/result_rows.h"
#include "core/simd_lanes.h"
#include "focal/core/error.h"
#include "focal/core/point_class.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/vertex_normals.h"
#include "kernels/eigen.h"
#include "kernels/local_shape.h"
#include "kernels/vec3.h"
#include "mesh/prepared_access.h"
#include "mesh/topology.h"
#include "normals/jet_fit.h"
#include "normals/jet_normals_from.h"
#include "normals/jet_points.h"
#include "normals/vertex_normals_from.h"

namespace focal {
namespace {

using namespace detail::jets;
using detail::SimdIsa;
using kernels::eigen_of;

/// One vertex's scratch in a batch.
struct LaneScratch {
  std::vector<int> ring;  ///< v and the vertices within `rings` edges, sorted
  Points points;
  Eigen::Vector3d n;   ///< the normal of the next fit's frame
  bool alive = false;  ///< every fit so far succeeded
};

/// A thread's scratch, reused across its batches: no allocation per vertex once warm.
struct JetScratch {
  std::vector<std::uint64_t> in_ring;  ///< gather_ring's marks
  LaneScratch lanes[kMaxLanes];
  std::vector<Point> zeros;  ///< an idle lane's points
  std::vector<double> terms;
  JetBatch batch;
  std::vector<double> scalar_terms;  ///< the scalar path's, for a lane that failed degree D
  JetBatch scalar;
};
Eigen::Vector3d jet_normal(const LocalJet& jet) {
  const kernels::Frame<double>& f = jet.frame;
  return (eigen_of(f.n) - jet.c[1] * eigen_of(f.x) - jet.c[2] * eigen_of(f.y)).normalized();
}

/// The jets' inputs: the mesh, the starting normals (unit or non-finite rows: no jet), the
/// options and the kernel of their degree.
struct JetInput {
  const PositionsRef& V;
  const Neighbourhoods& one;
  const NormalsRef& start;
  const JetOptions& o;
  TopDegreeKernel kernel;
  int width;                          ///< the kernel's lanes
  const std::vector<int>* sort_rows;  ///< gather_ring's
};

/// b.points of every lane, padded with (0, 0, 0) to b.points_max (JetBatch::points); an idle
/// lane's are all zero.
void pad_points(int width, JetScratch& s, JetBatch& b) {
  const auto n = static_cast<std::size_t>(b.points_max);
  if (s.zeros.size() < n) s.zeros.resize(n, Point{0.0, 0.0, 0.0});
  for (int l = 0; l < width; ++l) {
    LaneScratch& lane = s.lanes[l];
    if (b.count[l] == 0) {
      b.points[l] = s.zeros.data();
      continue;
    }
    lane.points.resize(n, Point{0.0, 0.0, 0.0});
    b.points[l] = lane.points.data();
  }
}

/// Each lane's degree-D fit from the kernel where it succeeded, the scalar path's lower degrees
/// where not; a lane with no fit is no longer alive.
void fit_heights(const JetInput& in, JetScratch& s, LocalJet* jets) {
  JetBatch& b = s.batch;
  b.points_max = 0;
  for (int l = 0; l < in.width; ++l) {
    const LaneScratch& lane = s.lanes[l];
    b.count[l] = lane.alive ? static_cast<int>(lane.points.size()) : 0;
    b.points_max = std::max(b.points_max, b.count[l]);
  }
  pad_points(in.width, s, b);
  const int D = in.o.degree, m = coefficient_count(D);
  s.terms.resize(static_cast<std::size_t>(b.points_max) * terms_stride(D) * in.width);
  b.terms = s.terms.data();
  in.kernel(b);
  for (int l = 0; l < in.width; ++l) {
    LaneScratch& lane = s.lanes[l];
    if (!lane.alive) continue;
    LocalJet& jet = jets[l];
    if (!b.solved[l]) {
      lane.alive =
          fit_lower_degrees(D, lane.points.data(), b.count[l], s.scalar, s.scalar_terms, jet);
      continue;
    }
    for (int k = 0; k < m; ++k) jet.c[k] = b.c[k * in.width + l];
    jet.degree = D;
    jet.points = b.count[l];
    jet.residual = residual_of(b.ssr[l], b.count[l], m, jet.scale);
  }
}

/// Fits `iterations` jets at each of the `count` vertices v[l] (count <= in.width) side by side,
/// starting from their rows of in.start; jets[l] receives the last (degree 0: none).
void fit_batch(const JetInput& in, const int* v, int count, JetScratch& s, LocalJet* jets) {
  for (int l = 0; l < in.width; ++l) {
    LaneScratch& lane = s.lanes[l];
    jets[l] = LocalJet{};
    lane.alive = l < count;
    if (!lane.alive) continue;
    lane.n = in.start.row(v[l]).transpose();
    lane.alive = lane.n.allFinite();
    if (lane.alive) gather_ring(in.one, v[l], in.o.rings, s.in_ring, in.sort_rows, lane.ring);
  }
  for (int it = 0; it < in.o.iterations; ++it) {
    for (int l = 0; l < in.width; ++l) {
      LaneScratch& lane = s.lanes[l];
      if (!lane.alive) continue;
      jets[l] = LocalJet{};
      jets[l].frame = kernels::frame_of(kernels::vec3_of(lane.n));
      jets[l].scale = gather_points(in.V, v[l], jets[l].frame, lane.ring, lane.points);
      lane.alive = jets[l].scale > 0.0;
    }
    fit_heights(in, s, jets);
    if (it + 1 == in.o.iterations) break;  // the last fit's normal is the caller's to compute
    for (int l = 0; l < in.width; ++l) {
      if (s.lanes[l].alive) s.lanes[l].n = jet_normal(jets[l]);
    }
  }
  for (int l = 0; l < in.width; ++l) {
    if (!s.lanes[l].alive) jets[l] = LocalJet{};
  }
}

void validate_options(const JetOptions& o) {
  if (o.rings < 1) throw InvalidInput("jet_normals: rings must be >= 1");
  if (o.degree < 1 || o.degree > kMaxDegree)
    throw InvalidInput("jet_normals: degree must be in [1, 4], got " + std::to_string(o.degree));
  if (o.iterations < 1) throw InvalidInput("jet_normals: iterations must be >= 1");
}

void validate(PositionsRef V, FacesRef F, const JetOptions& o) {
  validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), "jet_normals");
  validate_options(o);
}

/// Max's normals of a prepared mesh, on its incidence: the jets' starting frames.
RowMatrixX3d max_normals(const PreparedMesh& mesh) {
  return detail::vertex_normals_from(mesh.V(), mesh.F(), *detail::incidence(mesh),
                                     NormalWeighting::max, 0);
}

void validate_start(PositionsRef V, NormalsRef start) {
  if (start.rows() != V.rows())
    throw InvalidInput("jet_normals: " + std::to_string(start.rows()) + " start normals for " +
                       std::to_string(V.rows()) + " vertices");
  // |n|^2 within 2e-6 of 1: |n| within the 1e-6 that focal takes as unit elsewhere.
  for (Eigen::Index i = 0; i < start.rows(); ++i) {
    const double sq = start.row(i).squaredNorm();
    if (std::isfinite(sq) && std::abs(sq - 1.0) > 2e-6)
      throw InvalidInput("jet_normals: start normal " + std::to_string(i) + " has length " +
                         std::to_string(std::sqrt(sq)) + ", not 1");
  }
}

/// Runs body(k, jet) with the final jet (degree 0 where there is none) of vertex k, or of
/// vertex (*vertices)[k] when a list is given, the first fit in the frame of `start` (unit rows;
/// non-finite rows: no jet), in batches of the lane kernel of `isa` (none: one at a time). Every
/// lane is computed alone, so neither the batches nor the thread count change a bit.
template <class Body>
void for_each_jet(PositionsRef V, const Neighbourhoods& one, NormalsRef start, const JetOptions& o,
                  const std::vector<int>* vertices, std::optional<SimdIsa> isa, Body&& body,
                  const std::vector<int>* sort_rows = nullptr) {
  if (one.vertex_count() != V.rows())
    throw InvalidInput("jet_normals: the 1-ring has " + std::to_string(one.vertex_count()) +
                       " vertices, the mesh " + std::to_string(V.rows()));
  if (sort_rows && sort_rows->size() != static_cast<std::size_t>(V.rows()))
    throw InvalidInput("jet_normals: the rows to sort by are not the mesh's");
  const JetInput in{V,        one, start, o, top_degree_kernel(isa, o.degree), batch_width(isa),
                    sort_rows};
  const std::int64_t n = vertices ? static_cast<std::int64_t>(vertices->size()) : V.rows();
  detail::PerThread<JetScratch> scratch(0);
  detail::parallel_for_blocks(n, vertices ? 64 : 256, 0, [&](std::int64_t begin, std::int64_t end) {
    JetScratch& s = scratch.local();
    int v[kMaxLanes];
    LocalJet jets[kMaxLanes];
    for (std::int64_t first = begin; first < end; first += in.width) {
      const int count = static_cast<int>(std::min<std::int64_t>(in.width, end - first));
      for (int l = 0; l < count; ++l)
        v[l] = vertices ? (*vertices)[static_cast<std::size_t>(first + l)]
                        : static_cast<int>(first + l);
      fit_batch(in, v, count, s, jets);
      for (int l = 0; l < count; ++l) body(first + l, jets[l]);
    }
  });
}

/// Row k of `out` from `jet`.
void store_normal(const LocalJet& jet, Eigen::Index k, JetNormals& out) {
  out.degree[k] = jet.degree;
  out.residual[k] = jet.residual;
  if (jet.degree == 0) {
    out.N.row(k).setConstant(std::numeric_limits<double>::quiet_NaN());
  } else {
    out.N.row(k) = jet_normal(jet).transpose();
  }
}

JetNormals collect_normals(PositionsRef V, const Neighbourhoods& one, NormalsRef start,
                           const JetOptions& options, const std::vector<int>* vertices,
                           std::optional<SimdIsa> isa,
                           const std::vector<int>* sort_rows = nullptr) {
  JetNormals out;
  const Eigen::Index n = vertices ? static_cast<Eigen::Index>(vertices->size()) : V.rows();
  out.N.resize(n, 3);
  out.residual.resize(n);
  out.degree.resize(n);
  for_each_jet(
      V, one, start, options, vertices, isa,
      [&out](std::int64_t k, const LocalJet& jet) { store_normal(jet, k, out); }, sort_rows);
  return out;
}

/// Principal curvatures and directions of the graph z(x, y) at (0, 0), focal's sign convention.
void store_jet_curvature(const LocalJet& jet, int i, double zero_tolerance, CurvatureResult& r) {
  const Eigen::Vector2d g(jet.c[1], jet.c[2]);
  Eigen::Matrix2d hessian;
  hessian << 2.0 * jet.c[3], jet.c[4], jet.c[4], 2.0 * jet.c[5];
  hessian /= jet.scale;
  const Eigen::Matrix2d first = Eigen::Matrix2d::Identity() + g * g.transpose();
  // Second fundamental form for the upward normal; focal counts bending away from the normal
  // as positive (a sphere z = -(x^2 + y^2) / 2r has +1/r), hence the minus sign.
  const Eigen::Matrix2d second = -hessian / std::sqrt(1.0 + g.squaredNorm());
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d> eig(second, first);
  const Eigen::Vector3d n = jet_normal(jet);
  const Eigen::Vector2d v = eig.eigenvectors().col(1);  // of the larger eigenvalue
  const kernels::Frame<double>& f = jet.frame;
  Eigen::Vector3d d1 = eigen_of(f.x) * v.x() + eigen_of(f.y) * v.y() + eigen_of(f.n) * g.dot(v);
  d1 = (d1 - n * n.dot(d1)).normalized();
  r.k1[i] = eig.eigenvalues()[1];
  r.k2[i] = eig.eigenvalues()[0];
  r.H[i] = 0.5 * (r.k1[i] + r.k2[i]);
  r.K[i] = r.k1[i] * r.k2[i];
  r.d1.row(i) = d1.transpose();
  r.d2.row(i) = n.cross(d1).transpose();
  r.residual[i] = jet.residual;
  r.rays_used[i] = jet.points;
  r.rays_excluded[i] = 0;
  r.point_class[i] = kernels::classify(r.k1[i], r.k2[i], zero_tolerance, default_umbilic_tolerance);
}

}  // namespace

JetNormals jet_normals(const PreparedMesh& mesh, const JetOptions& options) {
  validate_options(options);
  const JetOptions& o = options;
  return collect_normals(mesh.V(), *detail::one_ring(mesh), max_normals(mesh), o, nullptr,
                         SimdIsa::best);
}

JetNormals jet_normals(PositionsRef V, FacesRef F, const JetOptions& options) {
  validate_options(options);
  return jet_normals(detail::PreparedAccess::make(V, F, std::nullopt, {}, "jet_normals"), options);
}

JetNormals jet_normals(PositionsRef V, FacesRef F, const Neighbourhoods& one_ring,
                       const JetOptions& options) {
  validate(V, F, options);
  return collect_normals(V, one_ring, vertex_normals(V, F, NormalWeighting::max), options, nullptr,
                         SimdIsa::best);
}

JetNormals jet_normals(PositionsRef V, FacesRef F, const Neighbourhoods& one_ring, NormalsRef start,
                       const JetOptions& options) {
  validate(V, F, options);
  validate_start(V, start);
  return collect_normals(V, one_ring, start, options, nullptr, SimdIsa::best);
}

JetNormals detail::jet_normals_from(PositionsRef V, const Neighbourhoods& one_ring,
                                    NormalsRef start, const JetOptions& options,
                                    std::optional<SimdIsa> isa, const std::vector<int>* sort_rows) {
  validate_options(options);
  return collect_normals(V, one_ring, start, options, nullptr, isa, sort_rows);
}

Eigen::VectorXd detail::jet_residuals_at(PositionsRef V, const Neighbourhoods& one_ring,
                                         NormalsRef start, const JetOptions& options,
                                         const std::vector<int>& vertices) {
  validate_options(options);
  Eigen::VectorXd out(static_cast<Eigen::Index>(vertices.size()));
  for_each_jet(V, one_ring, start, options, &vertices, SimdIsa::best,
               [&out](std::int64_t k, const LocalJet& jet) { out[k] = jet.residual; });
  return out;
}

JetNormals detail::jet_normals_at(PositionsRef V, const Neighbourhoods& one_ring, NormalsRef start,
                                  const JetOptions& options, const std::vector<int>& vertices,
                                  std::optional<SimdIsa> isa) {
  validate_options(options);
  return collect_normals(V, one_ring, start, options, &vertices, isa);
}

CurvatureResult jet_curvature(const PreparedMesh& mesh, const JetOptions& options) {
  if (options.degree < 2) throw InvalidInput("jet_curvature: degree must be >= 2");
  validate_options(options);
  const JetOptions& o = options;
  const PositionsRef& V = mesh.V();
  CurvatureResult r = detail::unwritten_result(V.rows());
  const double zero = default_zero_tolerance / mesh.mean_edge_length();
  const std::shared_ptr<const Neighbourhoods> one = detail::one_ring(mesh);
  const RowMatrixX3d start = max_normals(mesh);
  for_each_jet(V, *one, start, o, nullptr, SimdIsa::best, [&](std::int64_t i, const LocalJet& jet) {
    if (jet.degree < 2) {
      r.rays_used[i] = r.rays_excluded[i] = 0;
      return detail::store_undefined(r, i);
    }
    store_jet_curvature(jet, i, zero, r);
  });
  return r;
}

CurvatureResult jet_curvature(PositionsRef V, FacesRef F, const JetOptions& options) {
  if (options.degree < 2) throw InvalidInput("jet_curvature: degree must be >= 2");
  validate_options(options);
  return jet_curvature(detail::PreparedAccess::make(V, F, std::nullopt, {}, "jet_normals"),
                       options);
}

}  // namespace focal
