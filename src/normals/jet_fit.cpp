// The jets' lane kernels (jet_fit.h): the moments of a batch of vertices' points, the normal
// equations of each degree solved by LDL^T in Eigen's pivot order, their residuals, and the
// scalar path's lower degrees for a lane whose top degree failed. Compiled for AVX-512, AVX2
// and baseline x86-64 with the same bits on each (src/CMakeLists.txt: no FMA contraction).
#include "normals/jet_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/simd_lanes.h"

namespace focal::detail::jets {
namespace {

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

// Lane helpers that also take plain doubles (one lane): the scalar path is the same code.
template <class L>
constexpr int width = detail::lane_count<L>;

template <class L, class F>
FOCAL_LANE_INLINE L lanes_from(F f) {
  if constexpr (std::is_same_v<L, double>) {
    return f(0);
  } else {
    return detail::lanes_of<L>(f);
  }
}

template <class L>
FOCAL_LANE_INLINE auto lane_of(L x, int l) {
  if constexpr (std::is_arithmetic_v<L>) {
    return x;
  } else {
    return x[l];
  }
}

template <class L>
FOCAL_LANE_INLINE L abs_of(L x) {
  if constexpr (std::is_same_v<L, double>) {
    return std::abs(x);
  } else {
    return detail::lane_abs(x);
  }
}

/// The moments of every lane's points into b.xy, b.z, and their terms into b.terms. A lane's
/// points past its count are (0, 0, 0) with the constant monomial 0: each of their products is
/// +0, which leaves every sum's bits as they are (no sum of these starts at or reaches -0).
template <class L, int D>
FOCAL_LANE_INLINE void accumulate_moments(JetBatch& b) {
  constexpr int W = width<L>, kProducts = coefficient_count(2 * D), kTerms = coefficient_count(D);
  L xy[kProducts] = {}, z[kTerms] = {};
  const L count = lanes_from<L>([&](int l) { return static_cast<double>(b.count[l]); });
  const L one = detail::broadcast<L>(1.0), zero{};
  double* out = b.terms;
  for (int p = 0; p < b.points_max; ++p) {
    const auto field = [&](double Point::*f) FOCAL_LANE_LAMBDA {
      return lanes_from<L>([&](int l) { return b.points[l][p].*f; });
    };
    const L x = field(&Point::x), y = field(&Point::y), height = field(&Point::z);
    L xp[2 * D + 1], yp[2 * D + 1];
    xp[0] = detail::broadcast<L>(static_cast<double>(p)) < count ? one : zero;
    yp[0] = detail::broadcast<L>(1.0);
#pragma GCC unroll 16
    for (int k = 1; k <= 2 * D; ++k) xp[k] = xp[k - 1] * x, yp[k] = yp[k - 1] * y;
#pragma GCC unroll 64
    for (int q = 0; q < kProducts; ++q) {
      const L term = xp[kPowers.x[q]] * yp[kPowers.y[q]];
      xy[q] += term;
      if (q < kTerms) {
        z[q] += height * term;
        detail::store_lanes(out + q * W, term);
      }
    }
    detail::store_lanes(out + kTerms * W, height);
    out += terms_stride(D) * W;
  }
  for (int q = 0; q < kProducts; ++q) detail::store_lanes(b.xy + q * W, xy[q]);
  for (int q = 0; q < kTerms; ++q) detail::store_lanes(b.z + q * W, z[q]);
}

/// Eigen's LDLT's pivot order (the solver this replaced) for the m x m normal equations of one
/// lane (moment k at xy[k * stride]): at step k the largest |diagonal entry| of the rows left, as
/// stored before their update.
template <int m>
void pivot_order(const double* xy, int stride, int* perm) {
  double magnitude[m];
  for (int i = 0; i < m; ++i)
    perm[i] = i, magnitude[i] = std::abs(xy[kProductMoment.index[i][i] * stride]);
  for (int k = 0; k < m; ++k) {
    int best = k;
    for (int j = k + 1; j < m; ++j) best = magnitude[j] > magnitude[best] ? j : best;
    std::swap(magnitude[k], magnitude[best]);
    std::swap(perm[k], perm[best]);
  }
}

/// LDL^T of the permuted normal equations A y = r (A on and below the diagonal, overwritten by L
/// column by column), in the same operations per lane whatever the pivots: true per lane where
/// every pivot is non-zero, the smallest relative pivot is at least 1e-12 (a relative singular
/// value of 1e-6: below it the points are nearly collinear or conic, and their polynomial would
/// be fitted to rounding or noise) and y is finite. A failed lane computes on (NaN, inf) and is
/// reported, never used.
template <class L, int m>
FOCAL_LANE_INLINE auto solve_ldlt(L (&A)[m][m], const L (&r)[m], L (&y)[m]) {
  auto ok = L{} == L{};
  L d[m];
#pragma GCC unroll 16
  for (int k = 0; k < m; ++k) {
    L ld[m];  // L(k, j) d(j)
    L pivot = A[k][k];
#pragma GCC unroll 16
    for (int j = 0; j < k; ++j) {
      ld[j] = A[k][j] * d[j];
      pivot -= A[k][j] * ld[j];
    }
    ok = ok & (abs_of(pivot) > L{});  // also NaN
    d[k] = pivot;
    const L inverse = 1.0 / pivot;
#pragma GCC unroll 16
    for (int i = k + 1; i < m; ++i) {
      L s = A[i][k];
#pragma GCC unroll 16
      for (int j = 0; j < k; ++j) s -= A[i][j] * ld[j];
      A[i][k] = s * inverse;
    }
  }
  L smallest = abs_of(d[0]), largest = abs_of(d[0]);
  for (int k = 1; k < m; ++k) {
    const L e = abs_of(d[k]);
    smallest = e < smallest ? e : smallest;  // std::min and std::max, lane by lane
    largest = largest < e ? e : largest;
  }
  ok = ok & (smallest > 1e-12 * largest);
#pragma GCC unroll 16
  for (int i = 0; i < m; ++i) {
    y[i] = r[i];
#pragma GCC unroll 16
    for (int j = 0; j < i; ++j) y[i] -= A[i][j] * y[j];
  }
  for (int i = 0; i < m; ++i) y[i] /= d[i];
#pragma GCC unroll 16
  for (int i = m - 1; i >= 0; --i) {
#pragma GCC unroll 16
    for (int j = i + 1; j < m; ++j) y[i] -= A[j][i] * y[j];
  }
  for (int i = 0; i < m; ++i)
    ok = ok & (abs_of(y[i]) <= detail::broadcast<L>(std::numeric_limits<double>::max()));
  return ok;
}

/// Whether one lane's diagonal magnitudes (as pivot_order reads them) strictly decrease along
/// `perm`: pivot_order's order is then `perm` (with distinct magnitudes it is the one descending
/// order), found with m - 1 comparisons instead of its m (m - 1) / 2 and swaps.
template <int m>
bool decreasing_along(const double* xy, int stride, const int* perm) {
  const auto magnitude = [&](int i) { return std::abs(xy[kProductMoment.index[i][i] * stride]); };
  double previous = magnitude(perm[0]);
  for (int k = 1; k < m; ++k) {
    const double next = magnitude(perm[k]);
    if (!(previous > next)) return false;  // a tie or a NaN: pivot_order decides
    previous = next;
  }
  return true;
}

/// True where every lane's pivot order is lane 0's: neighbouring vertices mostly share theirs
/// (their moments differ little), and their systems are then gathered with one load per entry.
template <int W, int m>
FOCAL_LANE_INLINE bool same_pivot_order(const int (&perm)[W][m]) {
  bool same = true;
  for (int l = 1; l < W; ++l) {
    for (int i = 0; i < m; ++i) same &= perm[l][i] == perm[0][i];
  }
  return same;
}

/// Every lane's permuted system A (on and below the diagonal) and right-hand side r from its
/// moments, lane by lane in its own order perm[l], or with one load of all lanes per entry where
/// the orders are `shared` (the same values either way).
template <class L, int m>
FOCAL_LANE_INLINE void gather_system(const double* xy, const double* rhs,
                                     const int (&perm)[width<L>][m], bool shared, L (&A)[m][m],
                                     L (&r)[m]) {
  constexpr int W = width<L>;
  if (shared) {
    const int* p = perm[0];
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j <= i; ++j)
        A[i][j] = detail::load_lanes<L>(xy + kProductMoment.index[p[i]][p[j]] * W);
      r[i] = detail::load_lanes<L>(rhs + p[i] * W);
    }
    return;
  }
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j <= i; ++j) {
      A[i][j] = lanes_from<L>(
          [&](int l) { return xy[kProductMoment.index[perm[l][i]][perm[l][j]] * W + l]; });
    }
    r[i] = lanes_from<L>([&](int l) { return rhs[perm[l][i] * W + l]; });
  }
}

/// Solves every lane's m x m normal equations A c = rhs, A[j][k] = xy[kProductMoment[j][k]], by
/// LDL^T in its own pivot order (pivot_order): the matrix and right-hand side are gathered per
/// lane in that order, then factored in lanes. Fixed size and unrolled, the same operations in
/// every lane (Eigen's LDLT runs dynamic-size block code even for a fixed 10 x 10 matrix).
template <class L, int m>
FOCAL_LANE_INLINE auto solve_normal_equations(const double* xy, const double* rhs, double* c) {
  constexpr int W = width<L>;
  int perm[W][m];
  pivot_order<m>(xy, W, perm[0]);
  for (int l = 1; l < W; ++l) {
    if (decreasing_along<m>(xy + l, W, perm[0])) {
      std::copy(perm[0], perm[0] + m, perm[l]);
    } else {
      pivot_order<m>(xy + l, W, perm[l]);
    }
  }
  const bool shared = same_pivot_order<W, m>(perm);
  L A[m][m], r[m], y[m];
  gather_system<L, m>(xy, rhs, perm, shared, A, r);
  const auto ok = solve_ldlt<L, m>(A, r, y);
  if (shared) {
    for (int i = 0; i < m; ++i) detail::store_lanes(c + perm[0][i] * W, y[i]);
  } else {
    for (int l = 0; l < W; ++l) {
      for (int i = 0; i < m; ++i) c[perm[l][i] * W + l] = lane_of(y[i], l);
    }
  }
  return ok;
}

/// Sum of squared height residuals of the degree-d polynomial c (lane-minor) over every lane's
/// points, from the first coefficient_count(d) of their degree-D terms.
template <class L, int d, int D>
FOCAL_LANE_INLINE L squared_residuals(const JetBatch& b, const double* c) {
  constexpr int W = width<L>, m = coefficient_count(d), kTerms = coefficient_count(D);
  L coefficient[m];
  for (int k = 0; k < m; ++k) coefficient[k] = detail::load_lanes<L>(c + k * W);
  L ssr = {};
  const double* term = b.terms;
  for (int p = 0; p < b.points_max; ++p) {
    L height = {};
#pragma GCC unroll 16
    for (int k = 0; k < m; ++k) height += coefficient[k] * detail::load_lanes<L>(term + k * W);
    const L r = height - detail::load_lanes<L>(term + kTerms * W);
    ssr += r * r;
    term += terms_stride(D) * W;
  }
  return ssr;
}

/// The degree-d fit of every lane from b's moments into c (lane-minor) and its squared
/// residuals; true per lane where the lane has enough points and the system is well conditioned.
template <class L, int d, int D>
FOCAL_LANE_INLINE auto solve_degree(const JetBatch& b, double* c, L& ssr) {
  constexpr int m = coefficient_count(d);
  auto ok = solve_normal_equations<L, m>(b.xy, b.z, c);
  ok = ok & (lanes_from<L>([&](int l) { return static_cast<double>(b.count[l]); }) >= m);
  ssr = squared_residuals<L, d, D>(b, c);
  return ok;
}

/// The lane kernel: moments and the degree-D fit of every lane of b.
template <class L, int D>
FOCAL_LANE_INLINE void fit_top_degree(JetBatch& b) {
  accumulate_moments<L, D>(b);
  L ssr;
  const auto ok = solve_degree<L, D, D>(b, b.c, ssr);
  for (int l = 0; l < width<L>; ++l) {
    b.ssr[l] = lane_of(ssr, l);
    b.solved[l] = lane_of(ok, l) != 0;
  }
}

template <int D>
FOCAL_TARGET_AVX512 void fit_top_degree_avx512(JetBatch& b) {
  fit_top_degree<detail::Lanes8, D>(b);
}
template <int D>
FOCAL_TARGET_AVX2 void fit_top_degree_avx2(JetBatch& b) {
  fit_top_degree<detail::Lanes4, D>(b);
}
template <int D>
void fit_top_degree_baseline(JetBatch& b) {
  fit_top_degree<detail::Lanes2, D>(b);
}
template <int D>
void fit_top_degree_scalar(JetBatch& b) {
  fit_top_degree<double, D>(b);
}

template <int D>
TopDegreeKernel top_degree_kernel(std::optional<SimdIsa> isa) {
  if (!isa) return fit_top_degree_scalar<D>;
  return detail::kernel_for(*isa, fit_top_degree_avx512<D>, fit_top_degree_avx2<D>,
                            fit_top_degree_baseline<D>);
}

template <int D>
bool fit_lower_degrees(const Point* points, int n, JetBatch& scalar,
                       std::vector<double>& scalar_terms, LocalJet& jet) {
  JetBatch& b = scalar;
  b.points[0] = points;
  b.count[0] = b.points_max = n;
  scalar_terms.resize(static_cast<std::size_t>(n) * terms_stride(D));
  b.terms = scalar_terms.data();
  fit_top_degree<double, D>(b);
  const auto try_degree = [&](auto degree) {
    constexpr int d = decltype(degree)::value;
    double ssr = 0.0;
    if (!solve_degree<double, d, D>(b, jet.c, ssr)) return false;
    jet.degree = d;
    jet.points = n;
    jet.residual = residual_of(ssr, n, coefficient_count(d), jet.scale);
    return true;
  };
  if constexpr (D > 3) {
    if (try_degree(std::integral_constant<int, 3>{})) return true;
  }
  if constexpr (D > 2) {
    if (try_degree(std::integral_constant<int, 2>{})) return true;
  }
  if constexpr (D > 1) return try_degree(std::integral_constant<int, 1>{});
  return false;
}

}  // namespace

TopDegreeKernel top_degree_kernel(std::optional<SimdIsa> isa, int degree) {
  switch (degree) {
    case 4:
      return top_degree_kernel<4>(isa);
    case 3:
      return top_degree_kernel<3>(isa);
    case 2:
      return top_degree_kernel<2>(isa);
    default:
      return top_degree_kernel<1>(isa);
  }
}

bool solve_moments(int degree, JetBatch& b, int count) {
  const auto solve = [&](auto m) {
    return solve_normal_equations<double, decltype(m)::value>(b.xy, b.z, b.c) &&
           count >= decltype(m)::value;
  };
  switch (degree) {
    case 4:
      return solve(std::integral_constant<int, coefficient_count(4)>{});
    case 3:
      return solve(std::integral_constant<int, coefficient_count(3)>{});
    case 2:
      return solve(std::integral_constant<int, coefficient_count(2)>{});
    default:
      return solve(std::integral_constant<int, coefficient_count(1)>{});
  }
}

int batch_width(std::optional<SimdIsa> isa) {
  if (!isa) return 1;
  switch (detail::simd_isa(*isa)) {
    case SimdIsa::avx512:
      return static_cast<int>(sizeof(detail::Lanes8) / sizeof(double));
    case SimdIsa::avx2:
      return static_cast<int>(sizeof(detail::Lanes4) / sizeof(double));
    default:
      return static_cast<int>(sizeof(detail::Lanes2) / sizeof(double));
  }
}

double residual_of(double ssr, int n, int m, double scale) {
  return n > m ? std::sqrt(ssr / (n - m)) * scale : std::numeric_limits<double>::quiet_NaN();
}

bool fit_lower_degrees(int degree, const Point* points, int n, JetBatch& scalar,
                       std::vector<double>& scalar_terms, LocalJet& jet) {
  switch (degree) {
    case 4:
      return fit_lower_degrees<4>(points, n, scalar, scalar_terms, jet);
    case 3:
      return fit_lower_degrees<3>(points, n, scalar, scalar_terms, jet);
    case 2:
      return fit_lower_degrees<2>(points, n, scalar, scalar_terms, jet);
    default:
      return fit_lower_degrees<1>(points, n, scalar, scalar_terms, jet);
  }
}

}  // namespace focal::detail::jets
