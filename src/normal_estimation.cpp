#include "focal/normal_estimation.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "curvature_detail.h"
#include "focal/error.h"
#include "focal/neighbourhood.h"
#include "focal/normals.h"
#include "normal_rays_detail.h"
#include "parallel.h"

namespace focal {
namespace {

constexpr int kMaxDegree = 4;

constexpr int coefficient_count(int degree) { return (degree + 1) * (degree + 2) / 2; }

constexpr int kMaxCoefficients = coefficient_count(kMaxDegree);
using Coefficients = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCoefficients, 1>;

/// Monomials x^a y^b, a + b <= degree, by total degree then by falling power of x:
/// 1, x, y, x^2, xy, y^2, x^3, ... so that c[1], c[2] are the gradient and c[3..5] half the
/// Hessian's diagonal and its off-diagonal at (0, 0).
void monomials(double x, double y, int degree, double* out) {
  out[0] = 1.0;
  int previous = 0, k = 1;  // the monomials of degree d - 1 start at `previous`
  for (int d = 1; d <= degree; ++d) {
    const int start = k;
    for (int j = previous; j < start; ++j) out[k++] = out[j] * x;  // x^(d-b) y^b, b < d
    out[k++] = out[start - 1] * y;                                 // y^d
    previous = start;
  }
}

/// One vertex's fitted graph z = sum c_k m_k(x / s, y / s) * s in `frame` (origin at the vertex).
struct LocalJet {
  TangentFrame frame{Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
  double scale = 0.0;  ///< s: the neighbourhood radius the coordinates were divided by
  int degree = 0;      ///< 0: no valid fit
  int points = 0;
  double residual = std::numeric_limits<double>::quiet_NaN();
  Coefficients c;  ///< in scaled units
};

/// A vertex's neighbourhood and its offsets, reused across the vertices of a block.
struct JetScratch {
  std::vector<int> ring, frontier, next, merged;
  std::vector<Eigen::Vector3d> offsets;
};

/// The vertices within `rings` edges of v (v included), sorted. Gathered per vertex from the
/// 1-ring by sorted merges: no #V-sized marks, and much faster than building k_ring's CSR for
/// all vertices first.
void gather_ring(const Neighbourhoods& one, int v, int rings, JetScratch& s) {
  s.ring.assign(1, v);
  s.frontier.assign(1, v);
  for (int depth = 0; depth < rings && !s.frontier.empty(); ++depth) {
    s.next.clear();
    for (int u : s.frontier) s.next.insert(s.next.end(), one.begin(u), one.end(u));
    std::sort(s.next.begin(), s.next.end());
    s.next.erase(std::unique(s.next.begin(), s.next.end()), s.next.end());
    s.frontier.clear();
    std::set_difference(s.next.begin(), s.next.end(), s.ring.begin(), s.ring.end(),
                        std::back_inserter(s.frontier));
    s.merged.clear();
    std::merge(s.ring.begin(), s.ring.end(), s.frontier.begin(), s.frontier.end(),
               std::back_inserter(s.merged));
    std::swap(s.ring, s.merged);
  }
}

/// Offsets of the vertex itself (zero) and its ring in the frame, scaled by the largest one.
/// Non-finite neighbours are skipped. Returns the scale (0 when no usable neighbour).
double gather_offsets(PositionsRef V, int i, const TangentFrame& f, JetScratch& s) {
  s.offsets.assign(1, Eigen::Vector3d::Zero());
  const Eigen::Vector3d p = V.row(i).transpose();
  double scale = 0.0;
  for (int j : s.ring) {
    if (j == i) continue;
    const Eigen::Vector3d q = V.row(j).transpose() - p;
    if (!q.allFinite()) continue;
    s.offsets.emplace_back(f.x.dot(q), f.y.dot(q), f.n.dot(q));
    scale = std::max(scale, q.norm());
  }
  if (scale > 0.0) {
    for (Eigen::Vector3d& q : s.offsets) q /= scale;
  }
  return scale;
}

/// Least-squares fit of degree D if its normal equations are well conditioned. Normal equations
/// rather than QR, in fixed-size matrices: a quarter of the time, and with coordinates scaled to
/// the unit disc the squared condition number of a cubic stays far from rounding.
template <int D>
bool solve_degree(const JetScratch& s, LocalJet& jet) {
  constexpr int m = coefficient_count(D);
  using Vector = Eigen::Matrix<double, m, 1>;
  const auto n = static_cast<int>(s.offsets.size());
  if (n < m) return false;
  Eigen::Matrix<double, m, m> ata = Eigen::Matrix<double, m, m>::Zero();
  Vector atz = Vector::Zero();
  Vector a;
  for (const Eigen::Vector3d& q : s.offsets) {
    monomials(q.x(), q.y(), D, a.data());
    ata.template selfadjointView<Eigen::Lower>().rankUpdate(a);
    atz += q.z() * a;
  }
  const Eigen::LDLT<Eigen::Matrix<double, m, m>, Eigen::Lower> ldlt(ata);
  // A relative pivot below 1e-12 (a relative singular value below 1e-6) means nearly collinear
  // or conic points: their polynomial would be fitted to rounding or noise.
  const Vector pivots = ldlt.vectorD().cwiseAbs();
  if (ldlt.info() != Eigen::Success || !(pivots.minCoeff() > 1e-12 * pivots.maxCoeff()))
    return false;
  const Vector c = ldlt.solve(atz);
  if (!c.allFinite()) return false;
  double ssr = 0.0;
  for (const Eigen::Vector3d& q : s.offsets) {
    monomials(q.x(), q.y(), D, a.data());
    const double r = a.dot(c) - q.z();
    ssr += r * r;
  }
  jet.c = c;
  jet.degree = D;
  jet.points = n;
  jet.residual =
      n > m ? std::sqrt(ssr / (n - m)) * jet.scale : std::numeric_limits<double>::quiet_NaN();
  return true;
}

/// The fit of the highest degree <= `degree` that succeeds (too few points or a singular
/// system lowers the degree).
bool solve_heights(int degree, const JetScratch& s, LocalJet& jet) {
  return (degree >= 4 && solve_degree<4>(s, jet)) || (degree >= 3 && solve_degree<3>(s, jet)) ||
         (degree >= 2 && solve_degree<2>(s, jet)) || solve_degree<1>(s, jet);
}

/// Fits `iterations` jets at vertex i starting from the unit normal n0.
LocalJet fit_vertex(PositionsRef V, const Neighbourhoods& one, int i, Eigen::Vector3d n,
                    const JetOptions& o, JetScratch& s) {
  gather_ring(one, i, o.rings, s);
  LocalJet jet;
  for (int it = 0; it < o.iterations; ++it) {
    jet = LocalJet{};
    jet.frame = detail::frame_of(n);
    jet.scale = gather_offsets(V, i, jet.frame, s);
    if (!(jet.scale > 0.0) || !solve_heights(o.degree, s, jet)) return LocalJet{};
    n = (jet.frame.n - jet.c[1] * jet.frame.x - jet.c[2] * jet.frame.y).normalized();
  }
  return jet;
}

Eigen::Vector3d jet_normal(const LocalJet& jet) {
  return (jet.frame.n - jet.c[1] * jet.frame.x - jet.c[2] * jet.frame.y).normalized();
}

void validate(PositionsRef V, FacesRef F, const JetOptions& o) {
  validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), "jet_normals");
  if (o.rings < 1) throw InvalidInput("jet_normals: rings must be >= 1");
  if (o.degree < 1 || o.degree > kMaxDegree)
    throw InvalidInput("jet_normals: degree must be in [1, 4], got " + std::to_string(o.degree));
  if (o.iterations < 1) throw InvalidInput("jet_normals: iterations must be >= 1");
  if (o.threads < 0) throw InvalidInput("jet_normals: threads must be >= 0");
}

/// Runs body(i, jet) for every vertex with its final jet (degree 0 where there is none).
template <class Body>
void for_each_jet(PositionsRef V, FacesRef F, const Neighbourhoods& one, const JetOptions& o,
                  Body&& body) {
  validate(V, F, o);
  if (one.vertex_count() != V.rows())
    throw InvalidInput("jet_normals: the 1-ring has " + std::to_string(one.vertex_count()) +
                       " vertices, the mesh " + std::to_string(V.rows()));
  const RowMatrixX3d start = vertex_normals(V, F, NormalWeighting::max);
  detail::parallel_for_blocks(V.rows(), 256, o.threads, [&](std::int64_t begin, std::int64_t end) {
    JetScratch scratch;
    for (auto i = begin; i < end; ++i) {
      const Eigen::Vector3d n0 = start.row(i).transpose();
      const int v = static_cast<int>(i);
      body(v, n0.allFinite() ? fit_vertex(V, one, v, n0, o, scratch) : LocalJet{});
    }
  });
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
  Eigen::Vector3d d1 = jet.frame.x * v.x() + jet.frame.y * v.y() + jet.frame.n * g.dot(v);
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
  const CurvatureOptions defaults;
  r.point_class[i] = static_cast<std::uint8_t>(
      classify(r.k1[i], r.k2[i], zero_tolerance, defaults.umbilic_tolerance));
}

}  // namespace

JetNormals jet_normals(PositionsRef V, FacesRef F, const JetOptions& options) {
  validate(V, F, options);
  return jet_normals(V, F, vertex_adjacency(static_cast<int>(V.rows()), F), options);
}

JetNormals jet_normals(PositionsRef V, FacesRef F, const Neighbourhoods& one_ring,
                       const JetOptions& options) {
  JetNormals out;
  out.N.resize(V.rows(), 3);
  out.residual.resize(V.rows());
  out.degree.resize(V.rows());
  for_each_jet(V, F, one_ring, options, [&out](int i, const LocalJet& jet) {
    out.degree[i] = jet.degree;
    out.residual[i] = jet.residual;
    if (jet.degree == 0) {
      out.N.row(i).setConstant(std::numeric_limits<double>::quiet_NaN());
    } else {
      out.N.row(i) = jet_normal(jet).transpose();
    }
  });
  return out;
}

CurvatureResult jet_curvature(PositionsRef V, FacesRef F, const JetOptions& options) {
  if (options.degree < 2) throw InvalidInput("jet_curvature: degree must be >= 2");
  const auto n = V.rows();
  CurvatureResult r = detail::unwritten_result(n);
  const double zero = CurvatureOptions{}.zero_tolerance / mean_edge_length(V, F);
  validate(V, F, options);
  const Neighbourhoods one = vertex_adjacency(static_cast<int>(V.rows()), F);
  for_each_jet(V, F, one, options, [&](int i, const LocalJet& jet) {
    if (jet.degree < 2) {
      r.rays_used[i] = r.rays_excluded[i] = 0;
      return detail::store_undefined(r, i);
    }
    store_jet_curvature(jet, i, zero, r);
  });
  return r;
}

}  // namespace focal
