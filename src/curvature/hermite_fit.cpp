#include "curvature/hermite_fit.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <type_traits>
#include <utility>

#include "core/parallel.h"
#include "core/simd_lanes.h"
#include "curvature/polynomial_fit_detail.h"

namespace focal::detail {
namespace {

using polynomial::monomial_index;
using polynomial::monomials;
using polynomial::Table;
using polynomial::unroll;

/// The quartic's unknowns: the coefficients of the monomials x^a y^b of degree 2 to 4
/// (kHeightRight below lists them).
constexpr int kTerms = 12;

/// Points a fit takes at most (a 1-ring, or a 2-ring where the 1-ring is too small); more: no
/// fit.
constexpr std::size_t kMaxPoints = 96;

using Terms = polynomial::Vector<kTerms>;

/// The moments the normal matrix needs: heights' of degree 4 to 8 (weight 1 / d^4), slopes' of
/// degree 2 to 6 (weight 1 / d^2); the right side's: z u^a v^b of degree 2 to 4 (1 / d^4), the
/// slopes' zu, zv times u^a v^b of degree 1 to 3 (1 / d^2).
constexpr auto kHeightMoments = monomials<4, 8>();
constexpr auto kSlopeMoments = monomials<2, 6>();
constexpr auto kHeightRight = monomials<2, 4>();
constexpr auto kSlopeRight = monomials<1, 3>();
static_assert(kHeightRight.size() == kTerms);

using HeightMoments = Table<kHeightMoments>;
using SlopeMoments = Table<kSlopeMoments>;
using HeightRight = Table<kHeightRight>;
using SlopeRight = Table<kSlopeRight>;

/// Entry (i, j) of A^T A: heights[kH] + ai aj slopes[kU] + bi bj slopes[kV] (an index of -1:
/// no such term).
struct NormalEntry {
  int i, j, height, u_slope, v_slope;
  double u_factor, v_factor;
};
constexpr auto normal_entries() {
  std::array<NormalEntry, kTerms*(kTerms + 1) / 2> out{};
  std::size_t k = 0;
  for (int i = 0; i < kTerms; ++i) {
    for (int j = 0; j <= i; ++j) {
      const auto [ai, bi] = kHeightRight[static_cast<std::size_t>(i)];
      const auto [aj, bj] = kHeightRight[static_cast<std::size_t>(j)];
      const int a = ai + aj, b = bi + bj;
      out[k++] = {i,
                  j,
                  monomial_index(4, a, b),
                  ai > 0 && aj > 0 ? monomial_index(2, a - 2, b) : -1,
                  bi > 0 && bj > 0 ? monomial_index(2, a, b - 2) : -1,
                  static_cast<double>(ai * aj),
                  static_cast<double>(bi * bj)};
    }
  }
  return out;
}
constexpr auto kNormalEntries = normal_entries();

/// The least-squares system of the fit, kept as moments: a point at scaled offset (u, v) with
/// d = |(u, v)| gives a height row m_i / d^2 (m_i = u^a_i v^b_i) and two slope rows
/// (dm_i/du) / d, (dm_i/dv) / d, so every entry of A^T A is a moment of degree 4 to 8 weighted
/// by 1 / d^4 plus moments of degree 2 to 6 weighted by 1 / d^2, and A^T b is made of 30 more:
/// 90 sums a point instead of three rank-one updates of a 12 x 12 matrix.
///
/// Free terms: the height at the vertex (`free_height`: its position is known to third order
/// only, as a repaired spike's) and the gradient there (`free_gradient`: its normal is, as one
/// estimated from the positions) become unknowns too, eliminated from the normal equations
/// (their Schur complement). Their columns are 1 / d^2, u / d^2, v / d^2 in the height row and
/// 1 / d in the slope rows of the gradient's own component; their blocks are summed from the
/// rows themselves (few vertices need them).
struct System {
  bool free_height = false, free_gradient = false;
  Eigen::Matrix3d free_free = Eigen::Matrix3d::Zero();  ///< F^T F, terms (1, u, v)
  Eigen::Matrix<double, 3, kTerms> free_terms =
      Eigen::Matrix<double, 3, kTerms>::Zero();          ///< F^T A
  Eigen::Vector3d free_right = Eigen::Vector3d::Zero();  ///< F^T b
  std::array<double, kHeightMoments.size()> heights{};
  std::array<double, kSlopeMoments.size()> slopes{};
  std::array<double, kHeightRight.size()> height_right{};
  std::array<double, kSlopeRight.size()> u_right{}, v_right{};
  double btb = 0.0;
  int rows = 0;

  /// A point at scaled offset (u, v), height z, slopes (zu, zv).
  FOCAL_FIT_INLINE void add_point(double u, double v, double z, double zu, double zv,
                                  bool slopes_known) {
    const double g = 1.0 / (u * u + v * v), h = g * g;
    // A point whose normal is not known to full order gives its height row only.
    const double gs = slopes_known ? g : 0.0;
    const polynomial::Powers powers(u, v);
    const std::array<double, 9>&pu = powers.u, &pv = powers.v;
    const auto at = [&](auto table, auto k) FOCAL_FIT_LAMBDA {
      return polynomial::monomial_at<decltype(table)>(pu, pv, k);
    };
    const double hz = h * z, gu = gs * zu, gv = gs * zv;
    unroll<kHeightMoments.size()>(
        [&](auto k) FOCAL_FIT_LAMBDA { heights[k] += h * at(HeightMoments{}, k); });
    unroll<kSlopeMoments.size()>([&](auto k)
                                     FOCAL_FIT_LAMBDA { slopes[k] += gs * at(SlopeMoments{}, k); });
    unroll<kTerms>([&](auto k) FOCAL_FIT_LAMBDA { height_right[k] += hz * at(HeightRight{}, k); });
    unroll<kSlopeRight.size()>([&](auto k) FOCAL_FIT_LAMBDA {
      const double m = at(SlopeRight{}, k);
      u_right[k] += gu * m;
      v_right[k] += gv * m;
    });
    if (free_height || free_gradient) add_free(pu, pv, g, slopes_known, z, zu, zv);
    btb += hz * z + gs * (zu * zu + zv * zv);
    rows += slopes_known ? 3 : 1;
  }

  /// The free terms' blocks of a point's three rows (g = 1 / d^2).
  void add_free(const std::array<double, 9>& pu, const std::array<double, 9>& pv, double g,
                bool slopes_known, double z, double zu, double zv) {
    const double w = slopes_known ? std::sqrt(g) : 0.0, on = free_gradient ? 1.0 : 0.0;
    const Eigen::Vector3d height(free_height ? g : 0.0, on * g * pu[1], on * g * pv[1]);
    const Eigen::Vector3d du(0.0, on * w, 0.0), dv(0.0, 0.0, on * w);
    Eigen::Matrix<double, kTerms, 1> m, mu, mv;
    for (std::size_t i = 0; i < kTerms; ++i) {
      const auto a = static_cast<std::size_t>(kHeightRight[i][0]);
      const auto b = static_cast<std::size_t>(kHeightRight[i][1]);
      const auto k = static_cast<Eigen::Index>(i);
      m[k] = g * pu[a] * pv[b];
      mu[k] = a > 0 ? w * static_cast<double>(a) * pu[a - 1] * pv[b] : 0.0;
      mv[k] = b > 0 ? w * static_cast<double>(b) * pu[a] * pv[b - 1] : 0.0;
    }
    free_free += height * height.transpose() + du * du.transpose() + dv * dv.transpose();
    free_terms += height * m.transpose() + du * mu.transpose() + dv * mv.transpose();
    free_right += height * (g * z) + du * (w * zu) + dv * (w * zv);
  }

  [[nodiscard]] bool any_free() const { return free_height || free_gradient; }

  /// The inverse of the free terms' block on the free terms (zero rows and columns elsewhere).
  [[nodiscard]] Eigen::Matrix3d free_inverse() const {
    Eigen::Matrix3d out = Eigen::Matrix3d::Zero();
    if (free_height && free_gradient) return free_free.inverse();
    if (free_height) out(0, 0) = 1.0 / free_free(0, 0);
    if (free_gradient)
      out.bottomRightCorner<2, 2>() = free_free.bottomRightCorner<2, 2>().inverse();
    return out;
  }

  /// The free gradient at the solution c of the other terms: F^T F e = F^T (b - A c).
  [[nodiscard]] Eigen::Vector2d free_gradient_at(const Terms& c) const {
    const Eigen::Map<const Eigen::Matrix<double, kTerms, 1>> terms(c.data());
    const Eigen::Vector3d e = free_inverse() * (free_right - free_terms * terms);
    return e.tail<2>();
  }

  /// A^T A from the moments.
  [[nodiscard]] polynomial::Matrix<kTerms> normal_matrix() const {
    polynomial::Matrix<kTerms> out;
    unroll<kNormalEntries.size()>([&](auto k) FOCAL_FIT_LAMBDA {
      constexpr NormalEntry e = kNormalEntries[k];
      double x = heights[static_cast<std::size_t>(e.height)];
      if constexpr (e.u_slope >= 0) x += e.u_factor * slopes[static_cast<std::size_t>(e.u_slope)];
      if constexpr (e.v_slope >= 0) x += e.v_factor * slopes[static_cast<std::size_t>(e.v_slope)];
      out[static_cast<std::size_t>(e.i)][static_cast<std::size_t>(e.j)] = x;
      out[static_cast<std::size_t>(e.j)][static_cast<std::size_t>(e.i)] = x;
    });
    if (any_free()) {
      const Eigen::Matrix<double, kTerms, kTerms> schur =
          free_terms.transpose() * free_inverse() * free_terms;
      for (std::size_t i = 0; i < kTerms; ++i) {
        for (std::size_t j = 0; j < kTerms; ++j) {
          out[i][j] -= schur(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
        }
      }
    }
    return out;
  }

  /// A^T b from the moments: term u^a v^b's height row times z, its u-slope row (a u^(a-1) v^b)
  /// times zu, its v-slope row (b u^a v^(b-1)) times zv.
  [[nodiscard]] Terms right_side() const {
    Terms out;
    unroll<kTerms>([&](auto i) FOCAL_FIT_LAMBDA {
      constexpr int a = kHeightRight[i][0], b = kHeightRight[i][1];
      double x = height_right[i];
      if constexpr (a > 0) x += a * u_right[static_cast<std::size_t>(monomial_index(1, a - 1, b))];
      if constexpr (b > 0) x += b * v_right[static_cast<std::size_t>(monomial_index(1, a, b - 1))];
      out[i] = x;
    });
    if (any_free()) {
      const Eigen::Matrix<double, kTerms, 1> schur =
          free_terms.transpose() * (free_inverse() * free_right);
      for (std::size_t i = 0; i < kTerms; ++i) out[i] -= schur[static_cast<Eigen::Index>(i)];
    }
    return out;
  }

  /// The least-squares coefficients and the rows' RMS misfit there.
  struct Solution {
    Terms c;
    double misfit;
  };

  /// The least-squares solution (Cholesky of A^T A), or nothing where a pivot is below
  /// kHermiteMinPivot times the largest.
  [[nodiscard]] FOCAL_FIT_INLINE std::optional<Solution> solve() const {
    const Terms atb = right_side();
    const std::optional<Terms> c =
        polynomial::cholesky_solve<kTerms>(normal_matrix(), atb, kHermiteMinPivot);
    if (!c) return std::nullopt;
    // Less the free terms' part of b^T b.
    const double bb = any_free() ? btb - free_right.dot(free_inverse() * free_right) : btb;
    return Solution{*c, polynomial::rms_misfit(bb, *c, atb, rows)};
  }
};

/// Why a stencil gave no operator: too few rows to fix the quartic (a wider stencil may), or
/// rows it does not fit (a wider one would not help).
enum class Refusal { none, underdetermined, unfit };

/// The shape operator [a b; b c] of the fit over `stencil` in the vertex's frame; `refusal`
/// says why there is none.
FOCAL_FIT_INLINE std::optional<Eigen::Vector3d> hermite_operator(
    PositionsRef V, const RowMatrixX3d& N, const std::vector<char>& ok,
    const std::vector<int>& stencil, int v, const std::vector<char>& guessed,
    const TangentFrame& frame, bool free_height, bool free_gradient, Refusal& refusal, int& spare) {
  refusal = Refusal::underdetermined;
  if (stencil.size() < 5 || stencil.size() > kMaxPoints) return std::nullopt;
  refusal = Refusal::unfit;
  const Eigen::Vector3d p = V.row(v).transpose();
  // Offsets (x, y, z) and slopes in the frame, and the scale that makes the offsets O(1) (their
  // RMS tangential length).
  std::array<Eigen::Vector3d, kMaxPoints> local;
  std::array<Eigen::Vector2d, kMaxPoints> slope;
  double spread = 0.0;
  for (std::size_t k = 0; k < stencil.size(); ++k) {
    const int j = stencil[k];
    if (!ok[static_cast<std::size_t>(j)]) return std::nullopt;
    const Eigen::Vector3d m = N.row(j).transpose();
    const double mz = m.dot(frame.n);
    if (!(mz >= kHermiteMaxTurnCosine)) return std::nullopt;
    const Eigen::Vector3d e = V.row(j).transpose() - p;
    local[k] = {e.dot(frame.x), e.dot(frame.y), e.dot(frame.n)};
    slope[k] = {-m.dot(frame.x) / mz, -m.dot(frame.y) / mz};
    spread += local[k].head<2>().squaredNorm();
  }
  const double s = std::sqrt(spread / static_cast<double>(stencil.size()));
  if (!(s > 0.0)) return std::nullopt;
  System sys;
  sys.free_height = free_height;
  sys.free_gradient = free_gradient;
  for (std::size_t j = 0; j < stencil.size(); ++j) {
    const double u = local[j].x() / s, w = local[j].y() / s;
    if (!(u * u + w * w > 0.0)) return std::nullopt;
    sys.add_point(u, w, local[j].z() / s, slope[j].x(), slope[j].y(),
                  guessed.empty() || !guessed[static_cast<std::size_t>(stencil[j])]);
  }
  spare = sys.rows - (kTerms + (free_height ? 1 : 0) + (free_gradient ? 2 : 0));
  if (spare < 1) {
    refusal = Refusal::underdetermined;
    return std::nullopt;
  }
  const std::optional<System::Solution> solution = sys.solve();
  if (!solution) {
    refusal = Refusal::underdetermined;
    return std::nullopt;
  }
  const Terms& k = solution->c;
  if (!std::isfinite(k[0] + k[1] + k[2]) || !(solution->misfit <= kHermiteMaxMisfit)) {
    return std::nullopt;
  }
  refusal = Refusal::none;
  // h(x, y) = s h~(x / s, y / s): second derivatives are h~'s over s, first ones h~'s.
  const Eigen::Matrix2d hessian =
      (Eigen::Matrix2d() << 2.0 * k[0], k[1], k[1], 2.0 * k[2]).finished() / s;
  return free_gradient ? polynomial::graph_operator(hessian, sys.free_gradient_at(k))
                       : Eigen::Vector3d(-hessian(0, 0), -hessian(0, 1), -hessian(1, 1));
}

/// What prefer_hermite_fit reads (its arguments).
struct HermiteInputs : polynomial::FitInputs {
  const std::vector<char>& guessed;
};

/// prefer_hermite_fit on the vertices [begin, end).
FOCAL_FIT_INLINE void fit_rows(const HermiteInputs& in, std::int64_t begin, std::int64_t end,
                               CurvatureResult& fit, std::vector<char>& written) {
  std::vector<int> stencil;
  for (std::int64_t i = begin; i < end; ++i) {
    const auto v = static_cast<std::size_t>(i);
    const int vi = static_cast<int>(i);
    if (!polynomial::takes_vertex(in, fit, i)) continue;
    const TangentFrame frame = tangent_frame(in.N.row(i).transpose());
    Refusal refusal = Refusal::none;
    std::optional<Eigen::Vector3d> op;
    // The 1-ring first; the 2-ring where the 1-ring is too small to fix the quartic.
    const bool free_gradient = !in.guessed.empty() && in.guessed[v];
    const bool free_height = !in.moved.empty() && in.moved[v];
    const auto operator_over = [&](bool wide, int& spare) FOCAL_FIT_LAMBDA {
      polynomial::ring_stencil(in.one_ring, vi, wide, in.moved, stencil);
      return hermite_operator(in.V, in.N, in.ok, stencil, vi, in.guessed, frame, free_height,
                              free_gradient, refusal, spare);
    };
    bool on_one_ring = true;
    int spare = 0;
    for (const bool wide : {false, true}) {
      on_one_ring = !wide;
      op = operator_over(wide, spare);
      if (refusal != Refusal::underdetermined) break;
    }
    // A 1-ring fit with few rows to spare (a free gradient, guessed neighbours' single rows)
    // cannot show a spike or a wild normal in its misfit: it stands only where the 2-ring's
    // agrees.
    if (op.has_value() && on_one_ring && (free_gradient || spare < kHermiteSpareRows)) {
      const Eigen::Vector3d ring_operator = *op;
      op = operator_over(true, spare);
      if (op.has_value() && (ring_operator - *op).norm() <= kHermiteAgreement * op->norm()) {
        op = ring_operator;
      }
    }
    if (!op) continue;
    store_vertex(fit, i, frame, principal_from_symmetric((*op)[0], (*op)[1], (*op)[2]),
                 fit.residual[i], in.tol);
    written[v] = 1;
  }
}

// fit_rows for AVX2 and for baseline x86-64 (polynomial::fit_rows_for).
FOCAL_TARGET_AVX2 void fit_rows_avx2(const HermiteInputs& in, std::int64_t begin, std::int64_t end,
                                     CurvatureResult& fit, std::vector<char>& written) {
  fit_rows(in, begin, end, fit, written);
}
void fit_rows_baseline(const HermiteInputs& in, std::int64_t begin, std::int64_t end,
                       CurvatureResult& fit, std::vector<char>& written) {
  fit_rows(in, begin, end, fit, written);
}

}  // namespace

std::vector<char> prefer_hermite_fit(PositionsRef V, const RowMatrixX3d& N,
                                     const std::vector<char>& ok, const Neighbourhoods& one_ring,
                                     const VertexFaces& incidence, const std::vector<char>& keep,
                                     const std::vector<char>& moved,
                                     const std::vector<char>& guessed, double exact_residual,
                                     const ClassTolerances& tol, CurvatureResult& fit,
                                     SimdIsa isa) {
  const HermiteInputs in{{V, N, ok, keep, moved, one_ring, incidence, exact_residual, tol},
                         guessed};
  const auto rows = polynomial::fit_rows_for(isa, fit_rows_avx2, fit_rows_baseline);
  std::vector<char> written(static_cast<std::size_t>(V.rows()), 0);
  parallel_for_blocks(V.rows(), 256, 0, [&](std::int64_t begin, std::int64_t end) {
    rows(in, begin, end, fit, written);
  });
  return written;
}

}  // namespace focal::detail
