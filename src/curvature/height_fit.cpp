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

using polynomial::monomial_index;
using polynomial::monomials;
using polynomial::Table;
using polynomial::unroll;

/// Points a fit takes at most (a 2-ring); more: no fit.
constexpr std::size_t kMaxPoints = 96;

/// The least-squares system of the fit of the monomials of degree lo to 4 (lo = 1: the height
/// vanishes at the vertex; lo = 0: it is an unknown too), kept as moments: a point at scaled
/// offset (u, v), d = |(u, v)|, gives the row m_i / d^2, so every entry of A^T A is a moment
/// of degree 2 lo to 8 weighted by 1 / d^4, and A^T b the point's height times the terms.
template <int lo>
struct HeightSystem {
  static constexpr auto kTerms = monomials<lo, 4>();
  static constexpr auto kMoments = monomials<2 * lo, 8>();
  static constexpr std::size_t N = kTerms.size();
  using Terms = Table<kTerms>;
  using Moments = Table<kMoments>;

  std::array<double, kMoments.size()> moments{};
  polynomial::Vector<N> right{};
  double btb = 0.0;
  int rows = 0;

  FOCAL_FIT_INLINE void add_point(double u, double v, double z) {
    const double g = 1.0 / (u * u + v * v), h = g * g, hz = h * z;
    const polynomial::Powers powers(u, v);
    const std::array<double, 9>&pu = powers.u, &pv = powers.v;
    unroll<kMoments.size()>([&](auto k) FOCAL_FIT_LAMBDA {
      moments[k] += h * polynomial::monomial_at<Moments>(pu, pv, k);
    });
    unroll<N>([&](auto k)
                  FOCAL_FIT_LAMBDA { right[k] += hz * polynomial::monomial_at<Terms>(pu, pv, k); });
    btb += hz * z;
    ++rows;
  }

  [[nodiscard]] polynomial::Matrix<N> normal_matrix() const {
    polynomial::Matrix<N> out;
    unroll<N>([&](auto i) FOCAL_FIT_LAMBDA {
      unroll<i + 1>([&](auto j) FOCAL_FIT_LAMBDA {
        constexpr auto ei = kTerms[i];
        constexpr auto ej = kTerms[j];
        constexpr int k = monomial_index(2 * lo, ei[0] + ej[0], ei[1] + ej[1]);
        out[i][j] = out[j][i] = moments[static_cast<std::size_t>(k)];
      });
    });
    return out;
  }

  /// Coefficient of u^a v^b in a solution.
  static double coefficient(const polynomial::Vector<N>& c, int a, int b) {
    return c[static_cast<std::size_t>(monomial_index(lo, a, b))];
  }
};

/// A vertex's quartic fit: its shape operator [a b; b c], its rows' RMS misfit and that of the
/// cubic of the same rows.
struct HeightFit {
  Eigen::Vector3d op;
  double misfit, cubic_misfit;
};

/// The fit of `stencil` around v in `frame`, or nothing where the stencil does not fix the
/// quartic (too few points, or not all of them `ok` and within the turn guard of the frame).
template <int lo>
FOCAL_FIT_INLINE std::optional<HeightFit> height_fit(PositionsRef V, const RowMatrixX3d& N,
                                                     const std::vector<char>& ok,
                                                     const std::vector<int>& stencil, int v,
                                                     const TangentFrame& frame) {
  using System = HeightSystem<lo>;
  if (stencil.size() > kMaxPoints ||
      static_cast<int>(stencil.size()) < static_cast<int>(System::N) + kHeightSpareRows) {
    return std::nullopt;
  }
  const Eigen::Vector3d p = V.row(v).transpose();
  std::array<Eigen::Vector3d, kMaxPoints> local;
  double spread = 0.0;
  for (std::size_t k = 0; k < stencil.size(); ++k) {
    const int j = stencil[k];
    if (!ok[static_cast<std::size_t>(j)]) return std::nullopt;
    if (!(N.row(j).dot(frame.n) >= kHermiteMaxTurnCosine)) return std::nullopt;
    const Eigen::Vector3d e = V.row(j).transpose() - p;
    local[k] = {e.dot(frame.x), e.dot(frame.y), e.dot(frame.n)};
    spread += local[k].head<2>().squaredNorm();
  }
  // Offsets in units of their RMS tangential length: the system is O(1).
  const double s = std::sqrt(spread / static_cast<double>(stencil.size()));
  if (!(s > 0.0)) return std::nullopt;
  System sys;
  for (std::size_t k = 0; k < stencil.size(); ++k) {
    const double u = local[k].x() / s, w = local[k].y() / s;
    if (!(u * u + w * w > 0.0)) return std::nullopt;
    sys.add_point(u, w, local[k].z() / s);
  }
  const polynomial::Matrix<System::N> normal = sys.normal_matrix();
  const std::optional<polynomial::Vector<System::N>> c =
      polynomial::cholesky_solve<System::N>(normal, sys.right, kHermiteMinPivot);
  if (!c) return std::nullopt;
  // The cubic of the same rows: the quartic's normal equations' leading block (the terms are
  // ordered by degree).
  constexpr std::size_t kCubic = monomials<lo, 3>().size();
  polynomial::Matrix<kCubic> cubic_normal;
  polynomial::Vector<kCubic> cubic_right;
  for (std::size_t i = 0; i < kCubic; ++i) {
    cubic_right[i] = sys.right[i];
    for (std::size_t j = 0; j < kCubic; ++j) cubic_normal[i][j] = normal[i][j];
  }
  const std::optional<polynomial::Vector<kCubic>> cubic =
      polynomial::cholesky_solve<kCubic>(cubic_normal, cubic_right, kHermiteMinPivot);
  // h(x, y) = s h~(x / s, y / s): second derivatives are h~'s over s, first ones h~'s.
  const double xx = System::coefficient(*c, 2, 0), xy = System::coefficient(*c, 1, 1);
  const double yy = System::coefficient(*c, 0, 2);
  const Eigen::Matrix2d hessian = (Eigen::Matrix2d() << 2.0 * xx, xy, xy, 2.0 * yy).finished() / s;
  const Eigen::Vector2d gradient(System::coefficient(*c, 1, 0), System::coefficient(*c, 0, 1));
  if (!hessian.allFinite() || !gradient.allFinite()) return std::nullopt;
  return HeightFit{polynomial::graph_operator(hessian, gradient),
                   polynomial::rms_misfit(sys.btb, *c, sys.right, sys.rows),
                   cubic ? polynomial::rms_misfit(sys.btb, *cubic, cubic_right, sys.rows) : NAN};
}

using polynomial::FitInputs;

/// prefer_height_fit on the vertices [begin, end).
FOCAL_FIT_INLINE void fit_rows(const FitInputs& in, std::int64_t begin, std::int64_t end,
                               CurvatureResult& fit, std::vector<char>& written) {
  std::vector<int> stencil;
  for (std::int64_t i = begin; i < end; ++i) {
    const auto v = static_cast<std::size_t>(i);
    if (!polynomial::takes_vertex(in, fit, i)) continue;
    const int vi = static_cast<int>(i);
    const TangentFrame frame = tangent_frame(in.N.row(i).transpose());
    polynomial::ring_stencil(in.one_ring, vi, true, in.moved, stencil);
    const std::optional<HeightFit> f = !in.moved.empty() && in.moved[v]
                                           ? height_fit<0>(in.V, in.N, in.ok, stencil, vi, frame)
                                           : height_fit<1>(in.V, in.N, in.ok, stencil, vi, frame);
    // A spike or a fold left in the stencil (kHeightMaxMisfit), or noise that dominates the
    // fits' truncation here (kHeightMaxShare): the other steps' row stays.
    if (!f || !(f->misfit <= kHeightMaxMisfit) ||
        !(f->misfit <= kHeightMaxShare * f->cubic_misfit)) {
      continue;
    }
    const Eigen::Vector3d& op = f->op;
    store_vertex(fit, i, frame, principal_from_symmetric(op[0], op[1], op[2]), fit.residual[i],
                 in.tol);
    written[v] = 1;
  }
}

// fit_rows for AVX2 and for baseline x86-64 (polynomial::fit_rows_for).
FOCAL_TARGET_AVX2 void fit_rows_avx2(const FitInputs& in, std::int64_t begin, std::int64_t end,
                                     CurvatureResult& fit, std::vector<char>& written) {
  fit_rows(in, begin, end, fit, written);
}
void fit_rows_baseline(const FitInputs& in, std::int64_t begin, std::int64_t end,
                       CurvatureResult& fit, std::vector<char>& written) {
  fit_rows(in, begin, end, fit, written);
}

}  // namespace

std::vector<char> prefer_height_fit(PositionsRef V, const RowMatrixX3d& N,
                                    const std::vector<char>& ok, const Neighbourhoods& one_ring,
                                    const VertexFaces& incidence, const std::vector<char>& keep,
                                    const std::vector<char>& moved, double exact_residual,
                                    const ClassTolerances& tol, CurvatureResult& fit, SimdIsa isa) {
  const FitInputs in{V, N, ok, keep, moved, one_ring, incidence, exact_residual, tol};
  const auto rows = polynomial::fit_rows_for(isa, fit_rows_avx2, fit_rows_baseline);
  std::vector<char> written(static_cast<std::size_t>(V.rows()), 0);
  parallel_for_blocks(V.rows(), 256, 0, [&](std::int64_t begin, std::int64_t end) {
    rows(in, begin, end, fit, written);
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
  const std::optional<HeightFit> f = height_fit<1>(V, N, ok, stencil, v, tangent_frame(n));
  return f ? f->misfit / f->cubic_misfit : NAN;
}

}  // namespace focal::detail
