#include "curvature/height_fit.h"

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "core/parallel.h"
#include "core/simd_lanes.h"
#include "curvature/hermite_fit.h"
#include "curvature/polynomial_fit_detail.h"

namespace focal::detail {
namespace {

using polynomial::each;
using polynomial::monomial_index;
using polynomial::monomials;
using polynomial::run_start;

/// Points a fit takes at most (a 2-ring); more: no fit.
constexpr std::size_t kMaxPoints = 96;

/// The least-squares system of the fit of the monomials of degree lo to 4 (lo = 1: the height
/// vanishes at the vertex; lo = 0: it is an unknown too), kept as moments: a point at scaled
/// offset (u, v), d = |(u, v)|, gives the row m_i / d^2, so every entry of A^T A is a moment
/// of degree 2 lo to 8 weighted by 1 / d^4, and A^T b the point's height times the terms.
/// T: one vertex (double) or a vertex a lane (polynomial_fit_detail.h).
template <int lo, class T>
struct HeightSystem {
  static constexpr auto kTerms = monomials<lo, 4>();
  static constexpr auto kMoments = monomials<2 * lo, 8>();
  static constexpr std::size_t N = kTerms.size();
  static constexpr std::size_t kTermsAt = run_start<kTerms>();
  static constexpr std::size_t kMomentsAt = run_start<kMoments>();

  std::array<T, kMoments.size()> moments{};
  polynomial::Vector<N, T> right{};
  T btb{}, rows{};

  /// A point at scaled offset (u, v) and height z; none where not `active` (the sums take
  /// exact zeros: a lane whose stencil is shorter than its batch's longest).
  FOCAL_FIT_INLINE void add_point(const T& u, const T& v, const T& z, const MaskOf<T>& active) {
    const T zero = polynomial::constant<T>(0.0);
    const T g = polynomial::pick<T>(active, 1.0 / (u * u + v * v), zero), h = g * g, hz = h * z;
    const polynomial::AllMonomials<T> m(u, v);
    each<T, kMoments.size()>([&](auto k)
                                 FOCAL_FIT_LAMBDA { moments[k] += h * m.value[kMomentsAt + k]; });
    each<T, N>([&](auto k) FOCAL_FIT_LAMBDA { right[k] += hz * m.value[kTermsAt + k]; });
    btb += hz * z;
    rows += polynomial::pick<T>(active, polynomial::constant<T>(1.0), zero);
  }

  /// The moment of entry (i, j) of A^T A.
  static constexpr auto kNormalMoment = [] {
    std::array<std::array<std::size_t, N>, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
      for (std::size_t j = 0; j < N; ++j) {
        out[i][j] = static_cast<std::size_t>(
            monomial_index(2 * lo, kTerms[i][0] + kTerms[j][0], kTerms[i][1] + kTerms[j][1]));
      }
    }
    return out;
  }();

  [[nodiscard]] FOCAL_FIT_INLINE polynomial::Matrix<N, T> normal_matrix() const {
    polynomial::Matrix<N, T> out;
    each<T, N>([&](auto i) FOCAL_FIT_LAMBDA {
      each<T, N>([&](auto j) FOCAL_FIT_LAMBDA { out[i][j] = moments[kNormalMoment[i][j]]; });
    });
    return out;
  }

  /// Coefficient of u^a v^b in a solution.
  static const T& coefficient(const polynomial::Vector<N, T>& c, int a, int b) {
    return c[static_cast<std::size_t>(monomial_index(lo, a, b))];
  }
};

/// The quartic's solution and that of the cubic of the same rows (the quartic's normal
/// equations' leading block: the terms are ordered by degree), with their rows' RMS misfits.
template <int lo, class T>
struct HeightSolution {
  using System = HeightSystem<lo, T>;
  static constexpr std::size_t kCubic = monomials<lo, 3>().size();
  polynomial::Vector<System::N, T> c;
  T misfit, cubic_misfit;
  MaskOf<T> solved, cubic_solved;

  FOCAL_FIT_INLINE explicit HeightSolution(const System& sys) {
    polynomial::Matrix<System::N, T> normal = sys.normal_matrix();
    polynomial::Matrix<kCubic, T> cubic_normal;
    polynomial::Vector<kCubic, T> cubic_right;
    for (std::size_t i = 0; i < kCubic; ++i) {
      cubic_right[i] = sys.right[i];
      for (std::size_t j = 0; j < kCubic; ++j) cubic_normal[i][j] = normal[i][j];
    }
    c = polynomial::cholesky_solve<System::N, T>(normal, sys.right, kHermiteMinPivot, solved);
    const polynomial::Vector<kCubic, T> cubic = polynomial::cholesky_solve<kCubic, T>(
        cubic_normal, cubic_right, kHermiteMinPivot, cubic_solved);
    misfit = polynomial::rms_misfit<System::N, T>(sys.btb, c, sys.right, sys.rows);
    cubic_misfit = polynomial::rms_misfit<kCubic, T>(sys.btb, cubic, cubic_right, sys.rows);
  }
};

/// A stencil's points in the vertex's frame, scaled by `scale` (their RMS tangential length) so
/// that the offsets are O(1).
struct ScaledPoints {
  std::size_t size = 0;
  double scale = 0.0;
  std::array<double, kMaxPoints> u, v, z;
};

/// The points of `stencil` around v in `frame` for a fit of `terms` unknowns, or false where
/// the stencil does not fix the quartic (too few points, or not all of them `ok` and within the
/// turn guard of the frame).
FOCAL_FIT_INLINE bool scaled_points(PositionsRef V, const RowMatrixX3d& N,
                                    const std::vector<char>& ok, const std::vector<int>& stencil,
                                    int v, const TangentFrame& frame, std::size_t terms,
                                    ScaledPoints& out) {
  if (stencil.size() > kMaxPoints ||
      static_cast<int>(stencil.size()) < static_cast<int>(terms) + kHeightSpareRows) {
    return false;
  }
  const Eigen::Vector3d p = V.row(v).transpose();
  double spread = 0.0;
  for (std::size_t k = 0; k < stencil.size(); ++k) {
    const int j = stencil[k];
    if (!ok[static_cast<std::size_t>(j)]) return false;
    if (!(N.row(j).dot(frame.n) >= kHermiteMaxTurnCosine)) return false;
    const Eigen::Vector3d e = V.row(j).transpose() - p;
    const Eigen::Vector3d local(e.dot(frame.x), e.dot(frame.y), e.dot(frame.n));
    out.u[k] = local.x();
    out.v[k] = local.y();
    out.z[k] = local.z();
    spread += local.head<2>().squaredNorm();
  }
  out.size = stencil.size();
  // Offsets in units of their RMS tangential length: the system is O(1).
  out.scale = std::sqrt(spread / static_cast<double>(stencil.size()));
  const double s = out.scale;
  if (!(s > 0.0)) return false;
  for (std::size_t k = 0; k < out.size; ++k) {
    out.u[k] /= s;
    out.v[k] /= s;
    out.z[k] /= s;
    if (!(out.u[k] * out.u[k] + out.v[k] * out.v[k] > 0.0)) return false;
  }
  return true;
}

/// A vertex's quartic fit: its shape operator [a b; b c], its rows' RMS misfit and that of the
/// cubic of the same rows.
struct HeightFit {
  Eigen::Vector3d op;
  double misfit, cubic_misfit;
};

/// The fit from a vertex's solution (its curvature and gradient terms, solved or not) and its
/// points' scale, or nothing where it is not solved or not finite.
inline std::optional<HeightFit> height_fit_of(bool solved, double xx, double xy, double yy,
                                              double x, double y, double scale, double misfit,
                                              bool cubic_solved, double cubic_misfit) {
  if (!solved) return std::nullopt;
  // h(x, y) = s h~(x / s, y / s): second derivatives are h~'s over s, first ones h~'s.
  const Eigen::Matrix2d hessian =
      (Eigen::Matrix2d() << 2.0 * xx, xy, xy, 2.0 * yy).finished() / scale;
  const Eigen::Vector2d gradient(x, y);
  if (!hessian.allFinite() || !gradient.allFinite()) return std::nullopt;
  return HeightFit{polynomial::graph_operator(hessian, gradient), misfit,
                   cubic_solved ? cubic_misfit : NAN};
}

/// The fit of `stencil` around v in `frame`, or nothing where the stencil does not fix the
/// quartic (scaled_points) or its solution is not finite.
template <int lo>
FOCAL_FIT_INLINE std::optional<HeightFit> height_fit(PositionsRef V, const RowMatrixX3d& N,
                                                     const std::vector<char>& ok,
                                                     const std::vector<int>& stencil, int v,
                                                     const TangentFrame& frame,
                                                     ScaledPoints& points) {
  using System = HeightSystem<lo, double>;
  if (!scaled_points(V, N, ok, stencil, v, frame, System::N, points)) return std::nullopt;
  System sys;
  for (std::size_t k = 0; k < points.size; ++k) {
    sys.add_point(points.u[k], points.v[k], points.z[k], true);
  }
  const HeightSolution<lo, double> f(sys);
  const auto at = [&](int a, int b) { return System::coefficient(f.c, a, b); };
  return height_fit_of(f.solved, at(2, 0), at(1, 1), at(0, 2), at(1, 0), at(0, 1), points.scale,
                       f.misfit, f.cubic_solved, f.cubic_misfit);
}

using polynomial::FitInputs;

/// Whether fit `f` stands (a spike or a fold left in the stencil, kHeightMaxMisfit, or noise that
/// dominates the fits' truncation here, kHeightMaxShare, leave the other steps' row), and row i
/// of `fit` from it where it does.
inline void store_fit(const FitInputs& in, std::int64_t i, const TangentFrame& frame,
                      const std::optional<HeightFit>& f, CurvatureResult& fit,
                      std::vector<char>& written) {
  if (!f || !(f->misfit <= kHeightMaxMisfit) || !(f->misfit <= kHeightMaxShare * f->cubic_misfit)) {
    return;
  }
  const Eigen::Vector3d& op = f->op;
  store_vertex(fit, i, frame, principal_from_symmetric(op[0], op[1], op[2]), fit.residual[i],
               in.tol);
  written[static_cast<std::size_t>(i)] = 1;
}

using polynomial::lanes_in;

/// The vertices fitted a vertex a lane: those whose height at the vertex is not free (lo = 1).
template <std::size_t width>
using LaneBatch = polynomial::LaneBatch<ScaledPoints, width>;

/// The lanes' fits (height_fit<1> of each lane's points).
template <class L>
FOCAL_FIT_INLINE void fit_lanes(const FitInputs& in, LaneBatch<lanes_in<L>>& batch,
                                CurvatureResult& fit, std::vector<char>& written) {
  using System = HeightSystem<1, L>;
  const std::size_t longest =
      batch.pad_to_longest([](ScaledPoints& p, std::size_t k) FOCAL_FIT_LAMBDA {
        p.u[k] = p.v[k] = 1.0;
        p.z[k] = 0.0;
      });
  const auto lanes = [&](auto value)
                         FOCAL_LANE_LAMBDA { return polynomial::lane_values<L>(batch, value); };
  const L size =
      lanes([](const ScaledPoints& p) FOCAL_FIT_LAMBDA { return static_cast<double>(p.size); });
  System sys;
  for (std::size_t k = 0; k < longest; ++k) {
    const auto at =
        [&](const std::array<double, kMaxPoints> ScaledPoints::*field) FOCAL_LANE_LAMBDA {
          return lanes([&](const ScaledPoints& p) FOCAL_FIT_LAMBDA { return (p.*field)[k]; });
        };
    sys.add_point(at(&ScaledPoints::u), at(&ScaledPoints::v), at(&ScaledPoints::z),
                  polynomial::constant<L>(static_cast<double>(k)) < size);
  }
  const HeightSolution<1, L> f(sys);
  const auto at = [&](int a, int b, std::size_t l) { return System::coefficient(f.c, a, b)[l]; };
  for (std::size_t l = 0; l < batch.filled(); ++l) {
    store_fit(in, batch.row[l], batch.frame[l],
              height_fit_of(f.solved[l] != 0, at(2, 0, l), at(1, 1, l), at(0, 2, l), at(1, 0, l),
                            at(0, 1, l), batch.points[l].scale, f.misfit[l], f.cubic_solved[l] != 0,
                            f.cubic_misfit[l]),
              fit, written);
  }
  batch.size = 0;
}

/// prefer_height_fit on the vertices [begin, end), in lanes of L where `in_lanes`.
template <class L>
FOCAL_FIT_INLINE void fit_rows(const FitInputs& in, std::int64_t begin, std::int64_t end,
                               CurvatureResult& fit, std::vector<char>& written, bool in_lanes) {
  std::vector<int> stencil;
  ScaledPoints points;
  LaneBatch<lanes_in<L>> batch;
  for (std::int64_t i = begin; i < end; ++i) {
    const auto v = static_cast<std::size_t>(i);
    if (!polynomial::takes_vertex(in, fit, i)) continue;
    const int vi = static_cast<int>(i);
    const TangentFrame frame = tangent_frame(in.N.row(i).transpose());
    polynomial::ring_stencil(in.one_ring, vi, true, in.moved, stencil);
    if (!in.moved.empty() && in.moved[v]) {
      store_fit(in, i, frame, height_fit<0>(in.V, in.N, in.ok, stencil, vi, frame, points), fit,
                written);
    } else if (!in_lanes) {
      store_fit(in, i, frame, height_fit<1>(in.V, in.N, in.ok, stencil, vi, frame, points), fit,
                written);
    } else if (batch.size < lanes_in<L> &&
               scaled_points(in.V, in.N, in.ok, stencil, vi, frame, HeightSystem<1, L>::N,
                             batch.points[batch.size])) {
      batch.row[batch.size] = i;
      batch.frame[batch.size] = frame;
      if (++batch.size == lanes_in<L>) fit_lanes<L>(in, batch, fit, written);
    }
  }
  if (batch.size > 0) fit_lanes<L>(in, batch, fit, written);
}

// fit_rows for AVX2 and for baseline x86-64 (polynomial::fit_rows_for).
FOCAL_TARGET_AVX2 void fit_rows_avx2(const FitInputs& in, std::int64_t begin, std::int64_t end,
                                     CurvatureResult& fit, std::vector<char>& written,
                                     bool in_lanes) {
  fit_rows<Lanes4>(in, begin, end, fit, written, in_lanes);
}
void fit_rows_baseline(const FitInputs& in, std::int64_t begin, std::int64_t end,
                       CurvatureResult& fit, std::vector<char>& written, bool in_lanes) {
  fit_rows<Lanes2>(in, begin, end, fit, written, in_lanes);
}

}  // namespace

std::vector<char> prefer_height_fit(PositionsRef V, const RowMatrixX3d& N,
                                    const std::vector<char>& ok, const Neighbourhoods& one_ring,
                                    const VertexFaces& incidence, const std::vector<char>& keep,
                                    const std::vector<char>& moved, double exact_residual,
                                    const ClassTolerances& tol, CurvatureResult& fit, SimdIsa isa,
                                    bool in_lanes) {
  const FitInputs in{V, N, ok, keep, moved, one_ring, incidence, exact_residual, tol};
  const auto rows = polynomial::fit_rows_for(isa, fit_rows_avx2, fit_rows_baseline);
  std::vector<char> written(static_cast<std::size_t>(V.rows()), 0);
  parallel_for_blocks(V.rows(), 256, 0, [&](std::int64_t begin, std::int64_t end) {
    rows(in, begin, end, fit, written, in_lanes);
  });
  return written;
}

double height_truncation_share(PositionsRef V, const RowMatrixX3d& N, const std::vector<char>& ok,
                               const Neighbourhoods& one_ring, const VertexFaces& incidence, int v,
                               const Eigen::Vector3d& n) {
  if (!polynomial::closed_ring(one_ring, incidence, v) || !ok[static_cast<std::size_t>(v)])
    return NAN;
  std::vector<int> stencil;
  polynomial::ring_stencil(one_ring, v, true, {}, stencil);
  ScaledPoints points;
  const std::optional<HeightFit> f = height_fit<1>(V, N, ok, stencil, v, tangent_frame(n), points);
  return f ? f->misfit / f->cubic_misfit : NAN;
}

}  // namespace focal::detail
