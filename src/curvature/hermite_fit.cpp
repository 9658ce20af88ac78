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

using polynomial::each;
using polynomial::monomial_index;
using polynomial::monomials;

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

using polynomial::run_start;
constexpr std::size_t kHeightMomentsAt = run_start<kHeightMoments>();
constexpr std::size_t kSlopeMomentsAt = run_start<kSlopeMoments>();
constexpr std::size_t kHeightRightAt = run_start<kHeightRight>();
constexpr std::size_t kSlopeRightAt = run_start<kSlopeRight>();

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
/// 90 sums a point instead of three rank-one updates of a 12 x 12 matrix. T: one vertex
/// (double) or a vertex a lane (polynomial_fit_detail.h).
template <class T>
struct Moments {
  std::array<T, kHeightMoments.size()> heights{};
  std::array<T, kSlopeMoments.size()> slopes{};
  std::array<T, kHeightRight.size()> height_right{};
  std::array<T, kSlopeRight.size()> u_right{}, v_right{};
  T btb{};

  /// A point at scaled offset (u, v), height z, slopes (zu, zv); none where not `active` (the
  /// sums take exact zeros: a lane whose ring is shorter than its batch's longest).
  FOCAL_FIT_INLINE void add_point(const T& u, const T& v, const T& z, const T& zu, const T& zv,
                                  const MaskOf<T>& slopes_known, const MaskOf<T>& active) {
    const T zero = polynomial::constant<T>(0.0);
    const T g = polynomial::pick<T>(active, 1.0 / (u * u + v * v), zero), h = g * g;
    // A point whose normal is not known to full order gives its height row only.
    const T gs = polynomial::pick<T>(slopes_known, g, zero);
    const polynomial::AllMonomials<T> m(u, v);
    const T hz = h * z, gu = gs * zu, gv = gs * zv;
    each<T, kHeightMoments.size()>(
        [&](auto k) FOCAL_FIT_LAMBDA { heights[k] += h * m.value[kHeightMomentsAt + k]; });
    each<T, kSlopeMoments.size()>(
        [&](auto k) FOCAL_FIT_LAMBDA { slopes[k] += gs * m.value[kSlopeMomentsAt + k]; });
    each<T, kTerms>([&](auto k)
                        FOCAL_FIT_LAMBDA { height_right[k] += hz * m.value[kHeightRightAt + k]; });
    each<T, kSlopeRight.size()>([&](auto k) FOCAL_FIT_LAMBDA {
      u_right[k] += gu * m.value[kSlopeRightAt + k];
      v_right[k] += gv * m.value[kSlopeRightAt + k];
    });
    btb += hz * z + gs * (zu * zu + zv * zv);
  }

  /// A^T A from the moments.
  [[nodiscard]] FOCAL_FIT_INLINE polynomial::Matrix<kTerms, T> normal_matrix() const {
    polynomial::Matrix<kTerms, T> out;
    each<T, kNormalEntries.size()>([&](auto k) FOCAL_FIT_LAMBDA {
      const NormalEntry& e = kNormalEntries[k];
      T x = heights[static_cast<std::size_t>(e.height)];
      if (e.u_slope >= 0) x += e.u_factor * slopes[static_cast<std::size_t>(e.u_slope)];
      if (e.v_slope >= 0) x += e.v_factor * slopes[static_cast<std::size_t>(e.v_slope)];
      out[static_cast<std::size_t>(e.i)][static_cast<std::size_t>(e.j)] = x;
      out[static_cast<std::size_t>(e.j)][static_cast<std::size_t>(e.i)] = x;
    });
    return out;
  }

  /// A^T b from the moments: term u^a v^b's height row times z, its u-slope row (a u^(a-1) v^b)
  /// times zu, its v-slope row (b u^a v^(b-1)) times zv.
  [[nodiscard]] FOCAL_FIT_INLINE polynomial::Vector<kTerms, T> right_side() const {
    polynomial::Vector<kTerms, T> out;
    each<T, kTerms>([&](auto i) FOCAL_FIT_LAMBDA {
      const int a = kHeightRight[i][0], b = kHeightRight[i][1];
      T x = height_right[i];
      if (a > 0) {
        x +=
            static_cast<double>(a) * u_right[static_cast<std::size_t>(monomial_index(1, a - 1, b))];
      }
      if (b > 0) {
        x +=
            static_cast<double>(b) * v_right[static_cast<std::size_t>(monomial_index(1, a, b - 1))];
      }
      out[i] = x;
    });
    return out;
  }
};

/// The fit of one vertex: its moments, and the free terms where its height at the vertex
/// (`free_height`: its position is known to third order only, as a repaired spike's) or its
/// gradient there (`free_gradient`: its normal is, as one estimated from the positions) are
/// unknowns too, eliminated from the normal equations (their Schur complement). Their columns
/// are 1 / d^2, u / d^2, v / d^2 in the height row and 1 / d in the slope rows of the
/// gradient's own component; their blocks are summed from the rows themselves (few vertices
/// need them).
struct System : Moments<double> {
  bool free_height = false, free_gradient = false;
  Eigen::Matrix3d free_free = Eigen::Matrix3d::Zero();  ///< F^T F, terms (1, u, v)
  Eigen::Matrix<double, 3, kTerms> free_terms =
      Eigen::Matrix<double, 3, kTerms>::Zero();          ///< F^T A
  Eigen::Vector3d free_right = Eigen::Vector3d::Zero();  ///< F^T b
  int rows = 0;

  FOCAL_FIT_INLINE void add_point(double u, double v, double z, double zu, double zv,
                                  bool slopes_known) {
    Moments<double>::add_point(u, v, z, zu, zv, slopes_known, true);
    if (free_height || free_gradient) {
      const double g = 1.0 / (u * u + v * v);
      add_free(polynomial::Powers<double>(u, v), g, slopes_known, z, zu, zv);
    }
    rows += slopes_known ? 3 : 1;
  }

  /// The free terms' blocks of a point's three rows (g = 1 / d^2).
  void add_free(const polynomial::Powers<double>& powers, double g, bool slopes_known, double z,
                double zu, double zv) {
    const std::array<double, 9>&pu = powers.u, &pv = powers.v;
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

  /// A^T A of the other terms (less the free terms' part).
  [[nodiscard]] FOCAL_FIT_INLINE polynomial::Matrix<kTerms> reduced_normal_matrix() const {
    polynomial::Matrix<kTerms> out = normal_matrix();
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

  /// A^T b of the other terms (less the free terms' part).
  [[nodiscard]] FOCAL_FIT_INLINE Terms reduced_right_side() const {
    Terms out = right_side();
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
    const Terms atb = reduced_right_side();
    const std::optional<Terms> c =
        polynomial::cholesky_solve<kTerms>(reduced_normal_matrix(), atb, kHermiteMinPivot);
    if (!c) return std::nullopt;
    // Less the free terms' part of b^T b.
    const double bb = any_free() ? btb - free_right.dot(free_inverse() * free_right) : btb;
    return Solution{*c, polynomial::rms_misfit(bb, *c, atb, rows)};
  }
};

/// Why a stencil gave no operator: too few rows to fix the quartic (a wider stencil may), or
/// rows it does not fit (a wider one would not help).
enum class Refusal { none, underdetermined, unfit };

/// A stencil's points in the vertex's frame, scaled by `scale` (their RMS tangential length) so
/// that the offsets are O(1): the fit's rows before their weights.
struct ScaledPoints {
  std::size_t size = 0;
  double scale = 0.0;
  int rows = 0;  ///< 3 a point whose slopes are known (its normal not guessed), else 1
  std::array<double, kMaxPoints> u, v, z, zu, zv;
  std::array<bool, kMaxPoints> known;
};

/// The points of `stencil` for the fit at v, or false with `refusal`: underdetermined (fewer than
/// 5 points, or more than kMaxPoints) or unfit (a normal not `ok` or turned past
/// kHermiteMaxTurnCosine from the vertex's, offsets that vanish).
FOCAL_FIT_INLINE bool scaled_points(PositionsRef V, const RowMatrixX3d& N,
                                    const std::vector<char>& ok, const std::vector<int>& stencil,
                                    int v, const std::vector<char>& guessed,
                                    const TangentFrame& frame, ScaledPoints& out,
                                    Refusal& refusal) {
  refusal = Refusal::underdetermined;
  if (stencil.size() < 5 || stencil.size() > kMaxPoints) return false;
  refusal = Refusal::unfit;
  const Eigen::Vector3d p = V.row(v).transpose();
  double spread = 0.0;
  for (std::size_t k = 0; k < stencil.size(); ++k) {
    const int j = stencil[k];
    if (!ok[static_cast<std::size_t>(j)]) return false;
    const Eigen::Vector3d m = N.row(j).transpose();
    const double mz = m.dot(frame.n);
    if (!(mz >= kHermiteMaxTurnCosine)) return false;
    const Eigen::Vector3d e = V.row(j).transpose() - p;
    const Eigen::Vector3d local(e.dot(frame.x), e.dot(frame.y), e.dot(frame.n));
    out.u[k] = local.x();
    out.v[k] = local.y();
    out.z[k] = local.z();
    out.zu[k] = -m.dot(frame.x) / mz;
    out.zv[k] = -m.dot(frame.y) / mz;
    spread += local.head<2>().squaredNorm();
  }
  out.size = stencil.size();
  out.scale = std::sqrt(spread / static_cast<double>(stencil.size()));
  const double s = out.scale;
  if (!(s > 0.0)) return false;
  out.rows = 0;
  for (std::size_t k = 0; k < out.size; ++k) {
    out.u[k] /= s;
    out.v[k] /= s;
    out.z[k] /= s;
    if (!(out.u[k] * out.u[k] + out.v[k] * out.v[k] > 0.0)) return false;
    out.known[k] = guessed.empty() || !guessed[static_cast<std::size_t>(stencil[k])];
    out.rows += out.known[k] ? 3 : 1;
  }
  return true;
}

/// Whether a fit's coefficients stand: finite curvature terms, rows met within
/// kHermiteMaxMisfit.
inline bool fit_stands(double k0, double k1, double k2, double misfit) {
  return std::isfinite(k0 + k1 + k2) && misfit <= kHermiteMaxMisfit;
}

/// The Hessian of the height at the vertex from the fit of the scaled points: h(x, y) =
/// s h~(x / s, y / s), so second derivatives are h~'s over s.
inline Eigen::Matrix2d hessian_of(double k0, double k1, double k2, double s) {
  return (Eigen::Matrix2d() << 2.0 * k0, k1, k1, 2.0 * k2).finished() / s;
}

/// The shape operator [a b; b c] of a graph whose gradient vanishes at the vertex.
inline Eigen::Vector3d minus_hessian(const Eigen::Matrix2d& hessian) {
  return {-hessian(0, 0), -hessian(0, 1), -hessian(1, 1)};
}

/// The shape operator [a b; b c] of the fit over `points` in the vertex's frame; `refusal` says
/// why there is none (underdetermined where the rows do not fix the quartic, unfit where it does
/// not meet them); `spare`: the rows beyond the unknowns.
FOCAL_FIT_INLINE std::optional<Eigen::Vector3d> hermite_operator(const ScaledPoints& points,
                                                                 bool free_height,
                                                                 bool free_gradient,
                                                                 Refusal& refusal, int& spare) {
  System sys;
  sys.free_height = free_height;
  sys.free_gradient = free_gradient;
  for (std::size_t k = 0; k < points.size; ++k) {
    sys.add_point(points.u[k], points.v[k], points.z[k], points.zu[k], points.zv[k],
                  points.known[k]);
  }
  spare = sys.rows - (kTerms + (free_height ? 1 : 0) + (free_gradient ? 2 : 0));
  refusal = Refusal::underdetermined;
  if (spare < 1) return std::nullopt;
  const std::optional<System::Solution> solution = sys.solve();
  if (!solution) return std::nullopt;
  refusal = Refusal::unfit;
  const Terms& k = solution->c;
  if (!fit_stands(k[0], k[1], k[2], solution->misfit)) return std::nullopt;
  refusal = Refusal::none;
  const Eigen::Matrix2d hessian = hessian_of(k[0], k[1], k[2], points.scale);
  return free_gradient ? polynomial::graph_operator(hessian, sys.free_gradient_at(k))
                       : minus_hessian(hessian);
}

/// What prefer_hermite_fit reads (its arguments).
struct HermiteInputs : polynomial::FitInputs {
  const std::vector<char>& guessed;
};

/// Row i of `fit` from the operator `op` in `frame`.
inline void store_operator(const HermiteInputs& in, std::int64_t i, const TangentFrame& frame,
                           const Eigen::Vector3d& op, CurvatureResult& fit,
                           std::vector<char>& written) {
  store_vertex(fit, i, frame, principal_from_symmetric(op[0], op[1], op[2]), fit.residual[i],
               in.tol);
  written[static_cast<std::size_t>(i)] = 1;
}

/// prefer_hermite_fit at vertex i alone (`stencil` and `points`: scratch).
FOCAL_FIT_INLINE void fit_vertex(const HermiteInputs& in, std::int64_t i, std::vector<int>& stencil,
                                 ScaledPoints& points, CurvatureResult& fit,
                                 std::vector<char>& written) {
  const auto v = static_cast<std::size_t>(i);
  const int vi = static_cast<int>(i);
  const TangentFrame frame = tangent_frame(in.N.row(i).transpose());
  Refusal refusal = Refusal::none;
  std::optional<Eigen::Vector3d> op;
  // The 1-ring first; the 2-ring where the 1-ring is too small to fix the quartic.
  const bool free_gradient = !in.guessed.empty() && in.guessed[v];
  const bool free_height = !in.moved.empty() && in.moved[v];
  const auto operator_over = [&](bool wide, int& spare) FOCAL_FIT_LAMBDA {
    polynomial::ring_stencil(in.one_ring, vi, wide, in.moved, stencil);
    if (!scaled_points(in.V, in.N, in.ok, stencil, vi, in.guessed, frame, points, refusal)) {
      return std::optional<Eigen::Vector3d>();
    }
    return hermite_operator(points, free_height, free_gradient, refusal, spare);
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
  if (op) store_operator(in, i, frame, *op, fit, written);
}

using polynomial::lanes_in;

/// Points a lane's fit takes at most (the 1-rings whose 2-ring is searched, not sorted).
constexpr std::size_t kLanePoints = polynomial::kSearchedRing;

/// The vertices fitted a vertex a lane: those whose operator is their 1-ring's fit alone (no
/// free terms, at least kHermiteSpareRows rows to spare, at most kLanePoints points).
template <std::size_t width>
using LaneBatch = polynomial::LaneBatch<ScaledPoints, width>;

/// Whether vertex i goes to a lane of `batch` (added there), else to fit_vertex.
template <std::size_t width>
FOCAL_FIT_INLINE bool add_to_lanes(const HermiteInputs& in, std::int64_t i,
                                   std::vector<int>& stencil, LaneBatch<width>& batch) {
  const auto v = static_cast<std::size_t>(i);
  if ((!in.guessed.empty() && in.guessed[v]) || (!in.moved.empty() && in.moved[v]) ||
      batch.size >= width) {
    return false;
  }
  polynomial::ring_stencil(in.one_ring, static_cast<int>(i), false, in.moved, stencil);
  if (stencil.size() > kLanePoints) return false;
  const TangentFrame frame = tangent_frame(in.N.row(i).transpose());
  ScaledPoints& points = batch.points[batch.size];
  Refusal refusal = Refusal::none;
  if (!scaled_points(in.V, in.N, in.ok, stencil, static_cast<int>(i), in.guessed, frame, points,
                     refusal) ||
      points.rows - kTerms < kHermiteSpareRows) {
    return false;
  }
  batch.row[batch.size] = i;
  batch.frame[batch.size] = frame;
  ++batch.size;
  return true;
}

/// A lane's fit: the curvature terms, the misfit and whether the system was solved.
struct LaneFit {
  double k0, k1, k2, misfit;
  bool solved;
};
template <std::size_t width>
struct LaneFits {
  LaneFit lane[width] = {};
};

template <class L>
FOCAL_FIT_INLINE LaneFits<lanes_in<L>> fit_lanes(LaneBatch<lanes_in<L>>& batch) {
  const std::size_t longest =
      batch.pad_to_longest([](ScaledPoints& p, std::size_t k) FOCAL_FIT_LAMBDA {
        p.u[k] = p.v[k] = 1.0;
        p.z[k] = p.zu[k] = p.zv[k] = 0.0;
        p.known[k] = false;
      });
  const auto lanes = [&](auto value)
                         FOCAL_LANE_LAMBDA { return polynomial::lane_values<L>(batch, value); };
  const L size =
      lanes([](const ScaledPoints& p) FOCAL_FIT_LAMBDA { return static_cast<double>(p.size); });
  const L rows =
      lanes([](const ScaledPoints& p) FOCAL_FIT_LAMBDA { return static_cast<double>(p.rows); });
  const L zero = polynomial::constant<L>(0.0);
  Moments<L> sums;
  for (std::size_t k = 0; k < longest; ++k) {
    const auto at =
        [&](const std::array<double, kMaxPoints> ScaledPoints::*field) FOCAL_LANE_LAMBDA {
          return lanes([&](const ScaledPoints& p) FOCAL_FIT_LAMBDA { return (p.*field)[k]; });
        };
    const L known =
        lanes([&](const ScaledPoints& p) FOCAL_FIT_LAMBDA { return p.known[k] ? 1.0 : 0.0; });
    sums.add_point(at(&ScaledPoints::u), at(&ScaledPoints::v), at(&ScaledPoints::z),
                   at(&ScaledPoints::zu), at(&ScaledPoints::zv), known != zero,
                   polynomial::constant<L>(static_cast<double>(k)) < size);
  }
  const polynomial::Vector<kTerms, L> atb = sums.right_side();
  MaskOf<L> solved;
  polynomial::Matrix<kTerms, L> normal = sums.normal_matrix();
  const polynomial::Vector<kTerms, L> c =
      polynomial::cholesky_solve<kTerms, L>(normal, atb, kHermiteMinPivot, solved);
  const L misfit = polynomial::rms_misfit<kTerms, L>(sums.btb, c, atb, rows);
  LaneFits<lanes_in<L>> out;
  for (std::size_t l = 0; l < batch.filled(); ++l) {
    out.lane[l] = {c[0][l], c[1][l], c[2][l], misfit[l], solved[l] != 0};
  }
  return out;
}

/// prefer_hermite_fit on the vertices [begin, end), those that a lane takes (add_to_lanes) in
/// lanes of L where `in_lanes`.
template <class L>
FOCAL_FIT_INLINE void fit_rows(const HermiteInputs& in, std::int64_t begin, std::int64_t end,
                               CurvatureResult& fit, std::vector<char>& written, bool in_lanes) {
  std::vector<int> stencil;
  ScaledPoints points;
  LaneBatch<lanes_in<L>> batch;
  const auto flush = [&]() FOCAL_FIT_LAMBDA {
    const LaneFits<lanes_in<L>> fits = fit_lanes<L>(batch);
    for (std::size_t l = 0; l < batch.filled(); ++l) {
      const LaneFit& f = fits.lane[l];
      const std::int64_t i = batch.row[l];
      if (!f.solved) {  // the 1-ring does not fix the quartic: the 2-ring may
        fit_vertex(in, i, stencil, points, fit, written);
      } else if (fit_stands(f.k0, f.k1, f.k2, f.misfit)) {
        const Eigen::Matrix2d hessian = hessian_of(f.k0, f.k1, f.k2, batch.points[l].scale);
        store_operator(in, i, batch.frame[l], minus_hessian(hessian), fit, written);
      }
    }
    batch.size = 0;
  };
  for (std::int64_t i = begin; i < end; ++i) {
    if (!polynomial::takes_vertex(in, fit, i)) continue;
    if (in_lanes && add_to_lanes(in, i, stencil, batch)) {
      if (batch.size == lanes_in<L>) flush();
    } else {
      fit_vertex(in, i, stencil, points, fit, written);
    }
  }
  if (batch.size > 0) flush();
}

// fit_rows for AVX2 and for baseline x86-64 (polynomial::fit_rows_for).
FOCAL_TARGET_AVX2 void fit_rows_avx2(const HermiteInputs& in, std::int64_t begin, std::int64_t end,
                                     CurvatureResult& fit, std::vector<char>& written,
                                     bool in_lanes) {
  fit_rows<Lanes4>(in, begin, end, fit, written, in_lanes);
}
void fit_rows_baseline(const HermiteInputs& in, std::int64_t begin, std::int64_t end,
                       CurvatureResult& fit, std::vector<char>& written, bool in_lanes) {
  fit_rows<Lanes2>(in, begin, end, fit, written, in_lanes);
}

}  // namespace

std::vector<char> prefer_hermite_fit(PositionsRef V, const RowMatrixX3d& N,
                                     const std::vector<char>& ok, const Neighbourhoods& one_ring,
                                     const VertexFaces& incidence, const std::vector<char>& keep,
                                     const std::vector<char>& moved,
                                     const std::vector<char>& guessed, double exact_residual,
                                     const ClassTolerances& tol, CurvatureResult& fit, SimdIsa isa,
                                     bool in_lanes) {
  const HermiteInputs in{{V, N, ok, keep, moved, one_ring, incidence, exact_residual, tol},
                         guessed};
  const auto rows = polynomial::fit_rows_for(isa, fit_rows_avx2, fit_rows_baseline);
  std::vector<char> written(static_cast<std::size_t>(V.rows()), 0);
  parallel_for_blocks(V.rows(), 256, 0, [&](std::int64_t begin, std::int64_t end) {
    rows(in, begin, end, fit, written, in_lanes);
  });
  return written;
}

}  // namespace focal::detail
