#include "focal/normals/jets.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
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
#include "normals/jet_normals_from.h"
#include "normals/vertex_normals_from.h"

namespace focal {
namespace {

using detail::SimdIsa;
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

/// Two doubles as one SSE2 register: x.q and y.q in gather_points, with the same products and
/// sums per entry (and bits) as one at a time.
using Pair = double __attribute__((vector_size(2 * sizeof(double))));

/// Where the marked vertices of `ring` lie within a few words of marks of each other (on a mesh
/// whose nearby vertices have nearby indices), rewrites `ring` in ascending order by reading
/// those words, clearing them as it goes, and returns true: the sorted ring without a sort.
/// Otherwise leaves both as they are and returns false.
bool read_marks_in_order(std::vector<int>& ring, std::uint64_t* bits) {
  const auto [lowest, highest] = std::minmax_element(ring.begin(), ring.end());
  const auto first = static_cast<std::size_t>(*lowest) / 64;
  const auto last = static_cast<std::size_t>(*highest) / 64;
  if (last - first >= 4 * ring.size()) return false;
  int* out = ring.data();
  for (std::size_t k = first; k <= last; ++k) {
    for (std::uint64_t word = bits[k]; word != 0; word &= word - 1)
      *out++ = static_cast<int>(64 * k) + std::countr_zero(word);
    bits[k] = 0;
  }
  return true;
}

/// The vertices within `rings` edges of v (v included), sorted, into `ring`: breadth-first over
/// the 1-ring with marks (`in_ring`: one bit per vertex, allocated on first use, #V / 8 bytes: it
/// stays in cache; set while the vertex is in the neighbourhood being gathered, cleared after
/// it), then sorted so that the points, and hence the sums of the fit, keep the same order as
/// when the rings were merged as sorted lists (which cost 3.5 times as much). `sort_rows`: null,
/// or the vertices are a permuted copy's, sorted by their rows in the cloud (sort_rows[w]) so
/// that the sums keep the cloud's order (jet_normals_from).
void gather_ring(const Neighbourhoods& one, int v, int rings, std::vector<std::uint64_t>& in_ring,
                 const std::vector<int>* sort_rows, std::vector<int>& ring) {
  if (in_ring.empty()) in_ring.assign(static_cast<std::size_t>(one.vertex_count()) / 64 + 1, 0);
  std::uint64_t* bits = in_ring.data();
  const auto test_and_set = [bits](int w) {
    std::uint64_t& word = bits[static_cast<std::size_t>(w) / 64];
    const std::uint64_t bit = std::uint64_t{1} << (static_cast<unsigned>(w) % 64);
    const bool was = (word & bit) != 0;
    word |= bit;
    return was;
  };
  ring.assign(1, v);
  test_and_set(v);
  // Past the cap (rings >= 2) the search stops and v keeps no neighbours: no jet, as k_ring().
  // Checked once per vertex whose neighbours were added (the ring may pass the cap by those), not
  // once per neighbour: past it the ring is dropped either way.
  const std::size_t cap = rings >= 2 ? std::size_t{kMaxNeighbourhoodSize} + 1 : SIZE_MAX;
  std::size_t begin = 0;
  for (int depth = 0; depth < rings && begin < ring.size(); ++depth) {
    const std::size_t end = ring.size();
    for (std::size_t k = begin; k < end && ring.size() <= cap; ++k) {
      const int u = ring[k];
      for (const int* w = one.begin(u); w != one.end(u); ++w) {
        if (!test_and_set(*w)) ring.push_back(*w);
      }
    }
    begin = end;
  }
  if (!sort_rows && ring.size() <= cap && read_marks_in_order(ring, bits)) return;
  for (const int w : ring) bits[static_cast<std::size_t>(w) / 64] = 0;  // whole words: cheaper
  if (ring.size() > cap) ring.resize(1);
  if (sort_rows) {
    const int* row = sort_rows->data();
    detail::sort_small(ring.data(), ring.data() + ring.size(),
                       [row](int a, int b) { return row[a] < row[b]; });
  } else {
    detail::sort_small(ring.data(), ring.data() + ring.size(), std::less<>());
  }
}

/// A vertex's points: resize() leaves new entries unwritten (gather_points writes them).
using Points = std::vector<Point, detail::DefaultInitAllocator<Point>>;

/// The vertex itself (zero) and its ring in the frame, scaled by the largest offset, into
/// `points`; non-finite neighbours are skipped. Returns the scale (0 when no usable neighbour).
double gather_points(PositionsRef V, int i, const kernels::Frame<double>& f,
                     const std::vector<int>& ring, Points& points) {
  points.resize(ring.size() + 1);  // room for every point: written through a pointer, no checks
  Point* out = points.data();
  *out++ = {0.0, 0.0, 0.0};
  // Plain scalars: Eigen's 3-vectors pack into an SSE pair plus a scalar, which costs more than
  // the nine products here. x.q and y.q as one pair (the same products and sums per entry):
  // GCC paired them by itself or not, depending on how the frame was built.
  const double px = V(i, 0), py = V(i, 1), pz = V(i, 2);
  const Pair frame_x = {f.x.x, f.y.x}, frame_y = {f.x.y, f.y.y}, frame_z = {f.x.z, f.y.z};
  const double nx = f.n.x, ny = f.n.y, nz = f.n.z;
  double scale_sq = 0.0;
  for (const int j : ring) {
    if (j == i) continue;
    const double qx = V(j, 0) - px, qy = V(j, 1) - py, qz = V(j, 2) - pz;
    // All three finite (x - x is 0 for a finite x, NaN otherwise): one test instead of three.
    if (!((qx - qx) + (qy - qy) + (qz - qz) == 0.0)) continue;
    const Pair tangential = frame_x * qx + frame_y * qy + frame_z * qz;
    *out++ = {tangential[0], tangential[1], nx * qx + ny * qy + nz * qz};
    scale_sq = std::max(scale_sq, qx * qx + qy * qy + qz * qz);
  }
  points.resize(static_cast<std::size_t>(out - points.data()));
  const double scale = std::sqrt(scale_sq);  // the largest |q|: sqrt is monotonic
  if (scale > 0.0) {
    const double inv = 1.0 / scale;
    for (Point& q : points) q = {q.x * inv, q.y * inv, q.z * inv};
  }
  return scale;
}

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

constexpr int kMaxLanes = 8;

/// The fits of up to kMaxLanes vertices side by side, as plain data for the lane kernels (lane l:
/// the l-th vertex of a batch). Arrays of lanes are lane-minor: entry k of lane l at k * W + l,
/// W the kernel's lane count (1 for the scalar path).
///
/// The fit of degree D solves the normal equations of every degree up to D from moments: entry
/// (j, k) of the degree-d system is sum_i m_j(x_i) m_k(x_i) = the moment of the product
/// monomial, and the degree-d system is the leading block of the degree-D one (monomials are
/// numbered by degree). 28 moments per point for a cubic instead of 55 products, and a failed
/// cubic falls back to lower degrees without another pass over the points.
struct JetBatch {
  /// points_max points per lane: lane l's count[l] points (0: an idle lane), then (0, 0, 0), so
  /// that the kernel loads every lane's point p without asking whether it has one.
  const Point* points[kMaxLanes] = {};
  int count[kMaxLanes] = {};
  int points_max = 0;  ///< the largest count
  /// Per point p, terms_stride(D) lane vectors from terms + p * terms_stride(D) * W: the
  /// monomials of degree <= D (the residuals reuse them: same products, so the same bits as
  /// evaluating them again), then the height z; zero for a lane's points past its count.
  double* terms = nullptr;
  double xy[coefficient_count(2 * kMaxDegree) * kMaxLanes];  ///< sum x^a y^b, a + b <= 2D
  double z[kMaxCoefficients * kMaxLanes];                    ///< sum z x^a y^b, a + b <= D
  double c[kMaxCoefficients * kMaxLanes];                    ///< the degree-D fit, where solved
  double ssr[kMaxLanes];   ///< its sum of squared height residuals
  bool solved[kMaxLanes];  ///< count >= coefficient_count(D), well conditioned
};

constexpr int terms_stride(int degree) { return coefficient_count(degree) + 1; }

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
/// lane in that order, then factored in lanes. Fixed size and unrolled: Eigen's LDLT runs
/// dynamic-size block code even for a fixed 10 x 10 matrix (a fifth of the jets' time).
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

using TopDegreeKernel = void (*)(JetBatch&);

template <int D>
TopDegreeKernel top_degree_kernel(std::optional<SimdIsa> isa) {
  if (!isa) return fit_top_degree_scalar<D>;
  return detail::kernel_for(*isa, fit_top_degree_avx512<D>, fit_top_degree_avx2<D>,
                            fit_top_degree_baseline<D>);
}

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

/// The kernel's lane count: 1 without lanes.
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

/// The jet's residual from the squared residuals of its fit of m coefficients to n points.
double residual_of(double ssr, int n, int m, double scale) {
  return n > m ? std::sqrt(ssr / (n - m)) * scale : std::numeric_limits<double>::quiet_NaN();
}

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

/// The fit of the highest degree < D that succeeds, one lane alone, where degree D failed in
/// its batch: the scalar path (moments and degree D again, the same bits, then lower degrees).
template <int D>
bool fit_lower_degrees(const Point* points, int n, JetScratch& s, LocalJet& jet) {
  JetBatch& b = s.scalar;
  b.points[0] = points;
  b.count[0] = b.points_max = n;
  s.scalar_terms.resize(static_cast<std::size_t>(n) * terms_stride(D));
  b.terms = s.scalar_terms.data();
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

bool fit_lower_degrees(int degree, const Point* points, int n, JetScratch& s, LocalJet& jet) {
  switch (degree) {
    case 4:
      return fit_lower_degrees<4>(points, n, s, jet);
    case 3:
      return fit_lower_degrees<3>(points, n, s, jet);
    case 2:
      return fit_lower_degrees<2>(points, n, s, jet);
    default:
      return fit_lower_degrees<1>(points, n, s, jet);
  }
}

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
      lane.alive = fit_lower_degrees(D, lane.points.data(), b.count[l], s, jet);
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
  detail::PerThread<JetScratch> scratch(o.threads);
  detail::parallel_for_blocks(
      n, vertices ? 64 : 256, o.threads, [&](std::int64_t begin, std::int64_t end) {
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
  const JetOptions o = for_mesh(mesh, options);
  return collect_normals(mesh.V(), *detail::one_ring(mesh), max_normals(mesh, o.threads), o,
                         nullptr, SimdIsa::best);
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
                         options, nullptr, SimdIsa::best);
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
  const JetOptions o = for_mesh(mesh, options);
  const PositionsRef& V = mesh.V();
  CurvatureResult r = detail::unwritten_result(V.rows());
  const double zero = default_zero_tolerance / mesh.mean_edge_length();
  const std::shared_ptr<const Neighbourhoods> one = detail::one_ring(mesh);
  const RowMatrixX3d start = max_normals(mesh, o.threads);
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
  return jet_curvature(
      detail::PreparedAccess::make(V, F, std::nullopt, {.threads = options.threads}, "jet_normals"),
      options);
}

}  // namespace focal
