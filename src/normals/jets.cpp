#include "focal/normals/jets.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/fields_detail.h"
#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/core/point_class.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/normals.h"
#include "kernels/eigen.h"
#include "kernels/local_shape.h"
#include "kernels/vec3.h"
#include "mesh/normals_detail.h"
#include "mesh/prepared_detail.h"
#include "mesh/topology.h"
#include "normals/jets_detail.h"

namespace focal {
namespace {

using kernels::eigen_of;

constexpr int kMaxDegree = 4;

constexpr int coefficient_count(int degree) { return (degree + 1) * (degree + 2) / 2; }

constexpr int kMaxCoefficients = coefficient_count(kMaxDegree);

/// Monomials x^a y^b, a + b <= degree, by total degree t = a + b then by rising power b of y:
/// 1, x, y, x^2, xy, y^2, x^3, ... (monomial k = t (t + 1) / 2 + b), so that c[1], c[2] are the
/// gradient and c[3..5] half the Hessian's diagonal and its off-diagonal at (0, 0). The same
/// numbering indexes the moments of degree up to 2 * kMaxDegree.
constexpr int monomial_index(int t, int b) { return t * (t + 1) / 2 + b; }

/// kProductMoment[j][k]: the index of monomial j times monomial k.
struct ProductTable {
  int index[kMaxCoefficients][kMaxCoefficients];
};

constexpr ProductTable kProductMoment = [] {
  int degree[kMaxCoefficients] = {}, y_power[kMaxCoefficients] = {};
  for (int t = 0; t <= kMaxDegree; ++t) {
    for (int b = 0; b <= t; ++b)
      degree[monomial_index(t, b)] = t, y_power[monomial_index(t, b)] = b;
  }
  ProductTable p{};
  for (int j = 0; j < kMaxCoefficients; ++j) {
    for (int k = 0; k < kMaxCoefficients; ++k)
      p.index[j][k] = monomial_index(degree[j] + degree[k], y_power[j] + y_power[k]);
  }
  return p;
}();

/// One vertex's fitted graph z = sum c_k m_k(x / s, y / s) * s in `frame` (origin at the vertex).
struct LocalJet {
  /// The tangent frame of every estimator (kernels::frame_of).
  kernels::Frame<double> frame{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
  double scale = 0.0;  ///< s: the neighbourhood radius the coordinates were divided by
  int degree = 0;      ///< 0: no valid fit
  int points = 0;
  double residual = std::numeric_limits<double>::quiet_NaN();
  double c[kMaxCoefficients] = {};  ///< in scaled units; the first coefficient_count(degree)
};

/// A neighbourhood point in the vertex's frame, divided by the scale.
struct Point {
  double x, y, z;
};

/// Two doubles as one SSE2 register: the moments (and x.q, y.q in gather_points) are sums of
/// independent entries, added pairwise with the same per-entry operations (and bits) as one at a
/// time.
using Pair = double __attribute__((vector_size(2 * sizeof(double))));

/// A thread's scratch, reused across its vertices: no allocation per vertex once warm.
struct JetScratch {
  /// One bit per vertex, allocated on first use (#V / 8 bytes: it stays in cache): set while
  /// the vertex is in the neighbourhood being gathered, cleared after it.
  std::vector<std::uint64_t> in_ring;
  std::vector<int> ring;  ///< v and the vertices within `rings` edges, sorted
  std::vector<Point> points;
  std::vector<double> terms;  ///< each point's monomials (moments_of)
};

/// The vertices within `rings` edges of v (v included), sorted: breadth-first over the 1-ring
/// with marks, then sorted so that the points, and hence the sums of the fit, keep the same
/// order as when the rings were merged as sorted lists (which cost 3.5 times as much).
void gather_ring(const Neighbourhoods& one, int v, int rings, JetScratch& s) {
  if (s.in_ring.empty()) s.in_ring.assign(static_cast<std::size_t>(one.vertex_count()) / 64 + 1, 0);
  std::uint64_t* bits = s.in_ring.data();
  const auto test_and_set = [bits](int w) {
    std::uint64_t& word = bits[static_cast<std::size_t>(w) / 64];
    const std::uint64_t bit = std::uint64_t{1} << (static_cast<unsigned>(w) % 64);
    const bool was = (word & bit) != 0;
    word |= bit;
    return was;
  };
  s.ring.assign(1, v);
  test_and_set(v);
  // Past the cap (rings >= 2) the search stops and v keeps no neighbours: no jet, as k_ring().
  const std::size_t cap = rings >= 2 ? std::size_t{kMaxNeighbourhoodSize} + 1 : SIZE_MAX;
  std::size_t begin = 0;
  for (int depth = 0; depth < rings && begin < s.ring.size(); ++depth) {
    const std::size_t end = s.ring.size();
    for (std::size_t k = begin; k < end && s.ring.size() <= cap; ++k) {
      const int u = s.ring[k];
      for (const int* w = one.begin(u); w != one.end(u) && s.ring.size() <= cap; ++w) {
        if (!test_and_set(*w)) s.ring.push_back(*w);
      }
    }
    begin = end;
  }
  for (const int w : s.ring) bits[static_cast<std::size_t>(w) / 64] = 0;  // whole words: cheaper
  if (s.ring.size() > cap) s.ring.resize(1);
  detail::sort_small(s.ring.data(), s.ring.data() + s.ring.size(), std::less<>());
}

/// The vertex itself (zero) and its ring in the frame, scaled by the largest offset; non-finite
/// neighbours are skipped. Returns the scale (0 when no usable neighbour).
double gather_points(PositionsRef V, int i, const kernels::Frame<double>& f, JetScratch& s) {
  s.points.assign(1, Point{0.0, 0.0, 0.0});
  // Plain scalars: Eigen's 3-vectors pack into an SSE pair plus a scalar, which costs more than
  // the nine products here. x.q and y.q as one pair (the same products and sums per entry):
  // GCC paired them by itself or not, depending on how the frame was built.
  const double px = V(i, 0), py = V(i, 1), pz = V(i, 2);
  const Pair frame_x = {f.x.x, f.y.x}, frame_y = {f.x.y, f.y.y}, frame_z = {f.x.z, f.y.z};
  const double nx = f.n.x, ny = f.n.y, nz = f.n.z;
  double scale_sq = 0.0;
  for (const int j : s.ring) {
    if (j == i) continue;
    const double qx = V(j, 0) - px, qy = V(j, 1) - py, qz = V(j, 2) - pz;
    if (!std::isfinite(qx) || !std::isfinite(qy) || !std::isfinite(qz)) continue;
    const Pair tangential = frame_x * qx + frame_y * qy + frame_z * qz;
    s.points.push_back({tangential[0], tangential[1], nx * qx + ny * qy + nz * qz});
    scale_sq = std::max(scale_sq, qx * qx + qy * qy + qz * qz);
  }
  const double scale = std::sqrt(scale_sq);  // the largest |q|: sqrt is monotonic
  if (scale > 0.0) {
    const double inv = 1.0 / scale;
    for (Point& q : s.points) q = {q.x * inv, q.y * inv, q.z * inv};
  }
  return scale;
}

/// The normal equations of every degree up to D at once, from moments: entry (j, k) of the
/// degree-d system is sum_i m_j(x_i) m_k(x_i) = the moment of the product monomial, and the
/// degree-d system is the leading block of the degree-D one (monomials are numbered by degree).
/// 28 moments per point for a cubic instead of 55 products, and a failed cubic falls back to
/// lower degrees without another pass over the points.
template <int D>
struct Moments {
  static constexpr int kProducts = coefficient_count(2 * D);
  static constexpr int kCoefficients = coefficient_count(D);
  double xy[kProducts] = {};     ///< sum x^a y^b, a + b <= 2D
  double z[kCoefficients] = {};  ///< sum z x^a y^b, a + b <= D
};

constexpr int pairs_for(int count) { return (count + 1) / 2; }

/// Powers of x and y of every monomial of degree <= 2 kMaxDegree (the moments' numbering).
struct PowerTable {
  static constexpr int kCount = coefficient_count(2 * kMaxDegree);
  int x[kCount];
  int y[kCount];
};

constexpr PowerTable kPowers = [] {
  PowerTable p{};
  for (int t = 0; t <= 2 * kMaxDegree; ++t) {
    for (int b = 0; b <= t; ++b) p.x[monomial_index(t, b)] = t - b, p.y[monomial_index(t, b)] = b;
  }
  return p;
}();

/// The moments of the points; `terms` receives each point's monomials of degree <= D (the
/// residuals reuse them: same products, so the same bits as evaluating them again).
template <int D>
Moments<D> moments_of(const std::vector<Point>& points, std::vector<double>& terms) {
  constexpr int kProducts = Moments<D>::kProducts, kTerms = Moments<D>::kCoefficients;
  constexpr int kProductPairs = pairs_for(kProducts), kTermPairs = pairs_for(kTerms);
  terms.resize(points.size() * kTerms);
  Pair xy[kProductPairs] = {}, z[kTermPairs] = {};
  double* out = terms.data();
  for (const Point& p : points) {
    double xp[2 * D + 1], yp[2 * D + 1];
    xp[0] = yp[0] = 1.0;
    for (int k = 1; k <= 2 * D; ++k) xp[k] = xp[k - 1] * p.x, yp[k] = yp[k - 1] * p.y;
    // Each pair is assembled in registers from its two products: storing the products one by
    // one and loading them back as pairs would stall on store forwarding (8-byte stores read
    // by a 16-byte load), which cost more than the arithmetic.
    Pair term[kProductPairs];
#pragma GCC unroll 32
    for (int q = 0; q < kProductPairs; ++q) {
      const int lo = 2 * q, hi = 2 * q + 1;  // hi == kProducts: the zero padding entry
      term[q] = Pair{xp[kPowers.x[lo]] * yp[kPowers.y[lo]],
                     hi < kProducts ? xp[kPowers.x[hi]] * yp[kPowers.y[hi]] : 0.0};
    }
#pragma GCC unroll 32
    for (int q = 0; q < kProductPairs; ++q) xy[q] += term[q];
    const Pair pz = {p.z, p.z};
#pragma GCC unroll 32
    for (int q = 0; q < kTermPairs; ++q) z[q] += pz * term[q];
#pragma GCC unroll 32
    for (int k = 0; k < kTerms; ++k) out[k] = term[k / 2][k % 2];
    out += kTerms;
  }
  Moments<D> m;  // the pairs are the entries in order, and a possible padding entry last
  std::memcpy(m.xy, xy, sizeof m.xy);
  std::memcpy(m.z, z, sizeof m.z);
  return m;
}

/// Solves the m x m normal equations A c = rhs, A[j][k] = xy[kProductMoment[j][k]], by LDL^T;
/// false when A is not well conditioned. The pivot order is Eigen's LDLT's (the solver this
/// replaced): at step k the largest |diagonal entry| of the rows left, as stored before their
/// update. Same order, same pivots D, so the same vertices pass the rank test: a relative pivot
/// below 1e-12 (a relative singular value below 1e-6) means nearly collinear or conic points,
/// whose polynomial would be fitted to rounding or noise. Fixed size and unrolled: Eigen's LDLT
/// runs dynamic-size block code even for a fixed 10 x 10 matrix (a fifth of the jets' time).
template <int m>
bool solve_normal_equations(const double* xy, const double* rhs, double* c) {
  int perm[m];
  double magnitude[m];
  for (int i = 0; i < m; ++i) perm[i] = i, magnitude[i] = std::abs(xy[kProductMoment.index[i][i]]);
  for (int k = 0; k < m; ++k) {
    int best = k;
    for (int j = k + 1; j < m; ++j) best = magnitude[j] > magnitude[best] ? j : best;
    std::swap(magnitude[k], magnitude[best]);
    std::swap(perm[k], perm[best]);
  }
  double L[m][m];  // the permuted A on and below the diagonal, overwritten by L column by column
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j <= i; ++j) L[i][j] = xy[kProductMoment.index[perm[i]][perm[j]]];
  }
  double d[m];
#pragma GCC unroll 16
  for (int k = 0; k < m; ++k) {
    double ld[m];  // L(k, j) d(j)
    double pivot = L[k][k];
#pragma GCC unroll 16
    for (int j = 0; j < k; ++j) {
      ld[j] = L[k][j] * d[j];
      pivot -= L[k][j] * ld[j];
    }
    if (!(std::abs(pivot) > 0.0)) return false;  // also NaN
    d[k] = pivot;
    const double inverse = 1.0 / pivot;
#pragma GCC unroll 16
    for (int i = k + 1; i < m; ++i) {
      double s = L[i][k];
#pragma GCC unroll 16
      for (int j = 0; j < k; ++j) s -= L[i][j] * ld[j];
      L[i][k] = s * inverse;
    }
  }
  double smallest = std::abs(d[0]), largest = std::abs(d[0]);
  for (int k = 1; k < m; ++k) {
    smallest = std::min(smallest, std::abs(d[k]));
    largest = std::max(largest, std::abs(d[k]));
  }
  if (!(smallest > 1e-12 * largest)) return false;
  double y[m];
#pragma GCC unroll 16
  for (int i = 0; i < m; ++i) {
    y[i] = rhs[perm[i]];
#pragma GCC unroll 16
    for (int j = 0; j < i; ++j) y[i] -= L[i][j] * y[j];
  }
  for (int i = 0; i < m; ++i) y[i] /= d[i];
#pragma GCC unroll 16
  for (int i = m - 1; i >= 0; --i) {
#pragma GCC unroll 16
    for (int j = i + 1; j < m; ++j) y[i] -= L[j][i] * y[j];
  }
  bool finite = true;
  for (int i = 0; i < m; ++i) {
    c[perm[i]] = y[i];
    finite = finite && std::isfinite(y[i]);
  }
  return finite;
}

/// Sum of squared height residuals of the degree-d polynomial c over the points, from their
/// first m = coefficient_count(d) monomials (stored `stride` apart).
template <int d>
double squared_residuals(const std::vector<Point>& points, const std::vector<double>& terms,
                         int stride, const double* c) {
  constexpr int m = coefficient_count(d);
  double ssr = 0.0;
  const double* term = terms.data();
  for (const Point& p : points) {
    double height = 0.0;
    for (int k = 0; k < m; ++k) height += c[k] * term[k];
    const double r = height - p.z;
    ssr += r * r;
    term += stride;
  }
  return ssr;
}

/// Least-squares fit of degree d from the moments if the points determine it.
template <int d, int D>
bool solve_degree(const Moments<D>& moments, const std::vector<Point>& points,
                  const std::vector<double>& terms, LocalJet& jet) {
  constexpr int m = coefficient_count(d);
  const auto n = static_cast<int>(points.size());
  if (n < m || !solve_normal_equations<m>(moments.xy, moments.z, jet.c)) return false;
  jet.degree = d;
  jet.points = n;
  jet.residual =
      n > m ? std::sqrt(squared_residuals<d>(points, terms, Moments<D>::kCoefficients, jet.c) /
                        (n - m)) *
                  jet.scale
            : std::numeric_limits<double>::quiet_NaN();
  return true;
}

/// The fit of the highest degree <= D that succeeds (too few points or a singular system
/// lowers the degree).
template <int D>
bool solve_heights(const std::vector<Point>& points, std::vector<double>& terms, LocalJet& jet) {
  const Moments<D> m = moments_of<D>(points, terms);
  if constexpr (D >= 4) {
    if (solve_degree<4>(m, points, terms, jet)) return true;
  }
  if constexpr (D >= 3) {
    if (solve_degree<3>(m, points, terms, jet)) return true;
  }
  if constexpr (D >= 2) {
    if (solve_degree<2>(m, points, terms, jet)) return true;
  }
  return solve_degree<1>(m, points, terms, jet);
}

bool solve_heights(int degree, const std::vector<Point>& points, std::vector<double>& terms,
                   LocalJet& jet) {
  switch (degree) {
    case 4:
      return solve_heights<4>(points, terms, jet);
    case 3:
      return solve_heights<3>(points, terms, jet);
    case 2:
      return solve_heights<2>(points, terms, jet);
    default:
      return solve_heights<1>(points, terms, jet);
  }
}

Eigen::Vector3d jet_normal(const LocalJet& jet) {
  const kernels::Frame<double>& f = jet.frame;
  return (eigen_of(f.n) - jet.c[1] * eigen_of(f.x) - jet.c[2] * eigen_of(f.y)).normalized();
}

/// Fits `iterations` jets at vertex i starting from the unit normal n0.
LocalJet fit_vertex(PositionsRef V, const Neighbourhoods& one, int i, Eigen::Vector3d n,
                    const JetOptions& o, JetScratch& s) {
  gather_ring(one, i, o.rings, s);
  LocalJet jet;
  for (int it = 0; it < o.iterations; ++it) {
    jet = LocalJet{};
    jet.frame = kernels::frame_of(kernels::vec3_of(n));
    jet.scale = gather_points(V, i, jet.frame, s);
    if (!(jet.scale > 0.0) || !solve_heights(o.degree, s.points, s.terms, jet)) return LocalJet{};
    n = jet_normal(jet);
  }
  return jet;
}

void validate_options(const JetOptions& o) {
  if (o.rings < 1) throw InvalidInput("jet_normals: rings must be >= 1");
  if (o.degree < 1 || o.degree > kMaxDegree)
    throw InvalidInput("jet_normals: degree must be in [1, 4], got " + std::to_string(o.degree));
  if (o.iterations < 1) throw InvalidInput("jet_normals: iterations must be >= 1");
  if (o.threads < 0) throw InvalidInput("jet_normals: threads must be >= 0");
}

void validate(PositionsRef V, FacesRef F, const JetOptions& o) {
  validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), "jet_normals", o.threads);
  validate_options(o);
}

/// The options with threads resolved for `mesh`.
JetOptions for_mesh(const PreparedMesh& mesh, const JetOptions& options) {
  JetOptions o = options;
  o.threads = detail::threads_for(mesh, options.threads);
  return o;
}

/// Max's normals of a prepared mesh, on its incidence: the jets' starting frames.
RowMatrixX3d max_normals(const PreparedMesh& mesh, int threads) {
  return detail::vertex_normals_from(mesh.V(), mesh.F(), *detail::incidence(mesh),
                                     NormalWeighting::max, threads);
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

/// Runs body(i, jet) for every vertex with its final jet (degree 0 where there is none), the
/// first fit in the frame of `start` (validated unit rows; non-finite rows: no jet).
template <class Body>
void for_each_jet(PositionsRef V, const Neighbourhoods& one, NormalsRef start, const JetOptions& o,
                  Body&& body) {
  if (one.vertex_count() != V.rows())
    throw InvalidInput("jet_normals: the 1-ring has " + std::to_string(one.vertex_count()) +
                       " vertices, the mesh " + std::to_string(V.rows()));
  detail::PerThread<JetScratch> scratch(o.threads);
  detail::parallel_for_blocks(V.rows(), 256, o.threads, [&](std::int64_t begin, std::int64_t end) {
    JetScratch& s = scratch.local();
    for (auto i = begin; i < end; ++i) {
      const Eigen::Vector3d n0 = start.row(i).transpose();
      const int v = static_cast<int>(i);
      body(v, n0.allFinite() ? fit_vertex(V, one, v, n0, o, s) : LocalJet{});
    }
  });
}

JetNormals collect_normals(PositionsRef V, const Neighbourhoods& one, NormalsRef start,
                           const JetOptions& options) {
  JetNormals out;
  out.N.resize(V.rows(), 3);
  out.residual.resize(V.rows());
  out.degree.resize(V.rows());
  for_each_jet(V, one, start, options, [&out](int i, const LocalJet& jet) {
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
  const JetOptions o = for_mesh(mesh, options);
  return collect_normals(mesh.V(), *detail::one_ring(mesh), max_normals(mesh, o.threads), o);
}

JetNormals jet_normals(PositionsRef V, FacesRef F, const JetOptions& options) {
  validate_options(options);
  return jet_normals(
      detail::PreparedAccess::make(V, F, std::nullopt, {.threads = options.threads}, "jet_normals"),
      options);
}

JetNormals jet_normals(PositionsRef V, FacesRef F, const Neighbourhoods& one_ring,
                       const JetOptions& options) {
  validate(V, F, options);
  return collect_normals(V, one_ring, vertex_normals(V, F, NormalWeighting::max, options.threads),
                         options);
}

JetNormals jet_normals(PositionsRef V, FacesRef F, const Neighbourhoods& one_ring, NormalsRef start,
                       const JetOptions& options) {
  validate(V, F, options);
  validate_start(V, start);
  return collect_normals(V, one_ring, start, options);
}

JetNormals detail::jet_normals_from(PositionsRef V, const Neighbourhoods& one_ring,
                                    NormalsRef start, const JetOptions& options) {
  validate_options(options);
  return collect_normals(V, one_ring, start, options);
}

Eigen::VectorXd detail::jet_residuals_at(PositionsRef V, const Neighbourhoods& one_ring,
                                         NormalsRef start, const JetOptions& options,
                                         const std::vector<int>& vertices) {
  validate_options(options);
  Eigen::VectorXd out(static_cast<Eigen::Index>(vertices.size()));
  detail::PerThread<JetScratch> scratch(options.threads);
  detail::parallel_for_blocks(
      out.size(), 64, options.threads, [&](std::int64_t begin, std::int64_t end) {
        JetScratch& s = scratch.local();
        for (auto k = begin; k < end; ++k) {
          const int v = vertices[static_cast<std::size_t>(k)];
          const Eigen::Vector3d n0 = start.row(v).transpose();
          out[k] = n0.allFinite() ? fit_vertex(V, one_ring, v, n0, options, s).residual
                                  : std::numeric_limits<double>::quiet_NaN();
        }
      });
  return out;
}

JetNormals detail::jet_normals_at(PositionsRef V, const Neighbourhoods& one_ring, NormalsRef start,
                                  const JetOptions& options, const std::vector<int>& vertices) {
  validate_options(options);
  JetNormals out;
  const auto n = static_cast<Eigen::Index>(vertices.size());
  out.N.resize(n, 3);
  out.residual.resize(n);
  out.degree.resize(n);
  detail::PerThread<JetScratch> scratch(options.threads);
  detail::parallel_for_blocks(n, 64, options.threads, [&](std::int64_t begin, std::int64_t end) {
    JetScratch& s = scratch.local();
    for (auto k = begin; k < end; ++k) {
      const int v = vertices[static_cast<std::size_t>(k)];
      const Eigen::Vector3d n0 = start.row(v).transpose();
      const LocalJet jet = n0.allFinite() ? fit_vertex(V, one_ring, v, n0, options, s) : LocalJet{};
      out.degree[k] = jet.degree;
      out.residual[k] = jet.residual;
      if (jet.degree == 0) {
        out.N.row(k).setConstant(std::numeric_limits<double>::quiet_NaN());
      } else {
        out.N.row(k) = jet_normal(jet).transpose();
      }
    }
  });
  return out;
}

CurvatureResult jet_curvature(const PreparedMesh& mesh, const JetOptions& options) {
  if (options.degree < 2) throw InvalidInput("jet_curvature: degree must be >= 2");
  validate_options(options);
  const JetOptions o = for_mesh(mesh, options);
  const PositionsRef& V = mesh.V();
  CurvatureResult r = detail::unwritten_result(V.rows());
  const double zero = default_zero_tolerance / mesh.mean_edge_length();
  const std::shared_ptr<const Neighbourhoods> one = detail::one_ring(mesh);
  const RowMatrixX3d start = max_normals(mesh, o.threads);
  for_each_jet(V, *one, start, o, [&](int i, const LocalJet& jet) {
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
  return jet_curvature(
      detail::PreparedAccess::make(V, F, std::nullopt, {.threads = options.threads}, "jet_normals"),
      options);
}

}  // namespace focal
