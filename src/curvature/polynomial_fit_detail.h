#pragma once
// Internal to curvature/: what the polynomial height fits (hermite_fit.cpp, height_fit.cpp)
// share: their monomial tables, loops unrolled over the fits' fixed sizes, the Cholesky solve
// of their normal equations, the shape operator of a fitted graph, the rings they fit and the
// choice of their blocks' builds.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/simd_lanes.h"
#include "curvature/vertex_rows.h"
#include "focal/core/mesh.h"
#include "focal/curvature/normal_rays.h"
#include "focal/mesh/neighbourhood.h"
#include "mesh/topology.h"

// The fits' loops and lambdas are always inlined where the library is built for speed, so that
// a block's AVX2 build (fit_rows_for) holds the whole fit in wide registers. The fits pass no
// vectors by value, so a call left out of line is as correct, only slower: the sanitizer builds
// leave inlining to the compiler, whose instrumentation of the fully inlined and unrolled
// blocks would otherwise take GCC over half an hour a file.
#if defined(__SANITIZE_ADDRESS__)
#define FOCAL_FIT_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FOCAL_FIT_SANITIZED 1
#endif
#endif
#ifdef FOCAL_FIT_SANITIZED
#define FOCAL_FIT_INLINE inline
#define FOCAL_FIT_LAMBDA
#else
#define FOCAL_FIT_INLINE FOCAL_LANE_INLINE
#define FOCAL_FIT_LAMBDA FOCAL_LANE_LAMBDA
#endif

namespace focal::detail::polynomial {

/// f(integral_constant<0>), ..., f(integral_constant<N - 1>): loops over the fit's fixed sizes
/// unrolled, with every index a constant (inlined as FOCAL_FIT_INLINE says).
template <std::size_t N, class F>
FOCAL_FIT_INLINE void unroll(F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) FOCAL_FIT_LAMBDA {
    (f(std::integral_constant<std::size_t, I>{}), ...);
  }
  (std::make_index_sequence<N>{});
}

/// Exponents (a, b) of the monomials u^a v^b with lo <= a + b <= hi, by degree.
template <int lo, int hi>
constexpr auto monomials() {
  std::array<std::array<int, 2>, ((hi + 1) * (hi + 2) - lo * (lo + 1)) / 2> out{};
  std::size_t k = 0;
  for (int n = lo; n <= hi; ++n) {
    for (int a = n; a >= 0; --a) out[k++] = {a, n - a};
  }
  return out;
}

/// Index of u^a v^b in monomials<lo, hi>().
constexpr int monomial_index(int lo, int a, int b) {
  const int n = a + b;
  return (n * (n + 1) - lo * (lo + 1)) / 2 + (n - a);
}

/// The fits' arithmetic is written once for T = double (one vertex) and for T = a lane vector
/// of core/simd_lanes.h (a vertex a lane): the same IEEE operations in the same order, so each
/// lane has the bits of its vertex fitted alone. These helpers are the parts that differ. A
/// function that takes or returns a T by value is always inlined, also in the sanitizer builds:
/// left out of line it would be a baseline x86-64 function called from AVX2 code with another
/// ABI for its vectors.
template <class T>
constexpr bool kOneVertex = std::is_same_v<T, double>;

/// x in every lane.
template <class T>
FOCAL_LANE_INLINE T constant(double x) {
  if constexpr (kOneVertex<T>) {
    return x;
  } else {
    return broadcast<T>(x);
  }
}

/// c ? a : b per lane.
template <class T>
FOCAL_LANE_INLINE T pick(MaskOf<T> c, T a, T b) {
  return c ? a : b;
}

template <class T>
FOCAL_LANE_INLINE T square_root(T x) {
  if constexpr (kOneVertex<T>) {
    return std::sqrt(x);
  } else {
    return lane_sqrt(x);
  }
}

/// f(k) for k < N: unrolled with every k a constant for one vertex; a loop for lanes, whose wide
/// sums do not fit in registers anyway (and unrolled would cost GCC minutes a file).
template <class T, std::size_t N, class F>
FOCAL_FIT_INLINE void each(F&& f) {
  if constexpr (kOneVertex<T>) {
    unroll<N>(f);
  } else {
    for (std::size_t k = 0; k < N; ++k) f(k);
  }
}

/// f(j) for j < k, k an index of each().
template <class T, class K, class F>
FOCAL_FIT_INLINE void each_below(K k, F&& f) {
  if constexpr (kOneVertex<T>) {
    unroll<K::value>(f);
  } else {
    for (std::size_t j = 0; j < k; ++j) f(j);
  }
}

/// f(i) for k < i < N, ascending, k an index of each().
template <class T, std::size_t N, class K, class F>
FOCAL_FIT_INLINE void each_above(K k, F&& f) {
  if constexpr (kOneVertex<T>) {
    unroll<N - K::value - 1>([&](auto r) FOCAL_FIT_LAMBDA {
      f(std::integral_constant<std::size_t, K::value + 1 + decltype(r)::value>{});
    });
  } else {
    for (std::size_t i = k + 1; i < N; ++i) f(i);
  }
}

/// N - 1 - r for an index r of each().
template <class T, std::size_t N, class R>
FOCAL_FIT_INLINE auto reversed(R r) {
  if constexpr (kOneVertex<T>) {
    return std::integral_constant<std::size_t, N - 1 - R::value>{};
  } else {
    return N - 1 - r;
  }
}

/// The powers u^0 .. u^8 and v^0 .. v^8 of a point's scaled offset (the moments' degrees).
template <class T = double>
struct Powers {
  std::array<T, 9> u, v;
  FOCAL_FIT_INLINE Powers(const T& x, const T& y) {
    u[0] = v[0] = constant<T>(1.0);
    for (std::size_t k = 1; k < 9; ++k) {
      u[k] = u[k - 1] * x;
      v[k] = v[k - 1] * y;
    }
  }
};

/// Every monomial of degree 0 to 8, by degree, u's exponent descending (monomials<0, 8>()): the
/// fits' tables of monomials are runs of it.
constexpr auto kAllMonomials = monomials<0, 8>();

/// Where `table` starts in kAllMonomials (a compile-time error where it is not a run of it).
template <const auto& table>
constexpr std::size_t run_start() {
  const std::size_t start = static_cast<std::size_t>(monomial_index(0, table[0][0], table[0][1]));
  for (std::size_t k = 0; k < table.size(); ++k) {
    if (table[k] != kAllMonomials[start + k]) throw "not a run of kAllMonomials";
  }
  return start;
}

/// u^a v^b of a point's scaled offset (u, v) for every entry of kAllMonomials.
template <class T>
struct AllMonomials {
  std::array<T, kAllMonomials.size()> value;
  FOCAL_FIT_INLINE AllMonomials(const T& u, const T& v) {
    const Powers<T> powers(u, v);
    for (std::size_t n = 0, k = 0; n <= 8; ++n) {
      for (std::size_t b = 0; b <= n; ++b) value[k++] = powers.u[n - b] * powers.v[b];
    }
  }
};

/// A fit's block of vertices compiled for AVX2 where the CPU runs it and `isa` is not
/// baseline, else its baseline x86-64 build. The builds differ only in the width of their
/// registers (the fits' moments take fewer instructions in wider ones): AVX2 without the FMA
/// extension fuses no product into a sum, so both give the same bits.
template <class Kernel>
Kernel fit_rows_for(SimdIsa isa, Kernel avx2, Kernel baseline) {
  return isa != SimdIsa::baseline && simd_isa_available(SimdIsa::avx2) ? avx2 : baseline;
}

template <std::size_t N, class T = double>
using Vector = std::array<T, N>;
template <std::size_t N, class T = double>
using Matrix = std::array<Vector<N, T>, N>;

/// The solution of `l` c = `right` (symmetric, only the lower triangle read) by Cholesky, `l`
/// overwritten by its factor; `solved` is false where a pivot is not positive or below
/// `min_pivot` times the largest (the stencil does not fix the polynomial), and the solution is
/// then meaningless.
template <std::size_t N, class T>
FOCAL_FIT_INLINE Vector<N, T> cholesky_solve(Matrix<N, T>& l, const Vector<N, T>& right,
                                             double min_pivot, MaskOf<T>& solved) {
  T largest = constant<T>(0.0), smallest = constant<T>(INFINITY);
  MaskOf<T> positive = largest == largest;
  each<T, N>([&](auto k) FOCAL_FIT_LAMBDA {
    T pivot = l[k][k];
    each_below<T>(k, [&](auto j) FOCAL_FIT_LAMBDA { pivot -= l[k][j] * l[k][j]; });
    positive = positive & (pivot > constant<T>(0.0));
    largest = pick<T>(largest < pivot, pivot, largest);     // std::max(largest, pivot)
    smallest = pick<T>(pivot < smallest, pivot, smallest);  // std::min(smallest, pivot)
    l[k][k] = square_root(pivot);
    const T inverse = 1.0 / l[k][k];
    each_above<T, N>(k, [&](auto i) FOCAL_FIT_LAMBDA {
      T v = l[i][k];
      each_below<T>(k, [&](auto j) FOCAL_FIT_LAMBDA { v -= l[i][j] * l[k][j]; });
      l[i][k] = v * inverse;
    });
  });
  solved = positive & (smallest >= min_pivot * largest);
  Vector<N, T> c = right;
  each<T, N>([&](auto i) FOCAL_FIT_LAMBDA {  // L y = right
    each_below<T>(i, [&](auto j) FOCAL_FIT_LAMBDA { c[i] -= l[i][j] * c[j]; });
    c[i] /= l[i][i];
  });
  each<T, N>([&](auto r) FOCAL_FIT_LAMBDA {  // L^T c = y
    const auto i = reversed<T, N>(r);
    each_above<T, N>(i, [&](auto k) FOCAL_FIT_LAMBDA { c[i] -= l[k][i] * c[k]; });
    c[i] /= l[i][i];
  });
  return c;
}

/// cholesky_solve of one vertex, or nothing where it is not solved.
template <std::size_t N>
FOCAL_FIT_INLINE std::optional<Vector<N>> cholesky_solve(Matrix<N> normal, const Vector<N>& right,
                                                         double min_pivot) {
  bool solved = false;
  const Vector<N> c = cholesky_solve<N, double>(normal, right, min_pivot, solved);
  if (!solved) return std::nullopt;
  return c;
}

/// The rows' RMS misfit at the least-squares solution c of A c = b: r^T r = b^T b - c^T A^T b.
template <std::size_t N, class T>
FOCAL_LANE_INLINE T rms_misfit(const T& btb, const Vector<N, T>& c, const Vector<N, T>& atb,
                               const T& rows) {
  T ctb = constant<T>(0.0);
  for (std::size_t i = 0; i < N; ++i) ctb += c[i] * atb[i];
  const T spread = btb - ctb;
  const T zero = constant<T>(0.0);
  return square_root(pick<T>(zero < spread, spread, zero) / rows);  // std::max(0, spread)
}
template <std::size_t N>
FOCAL_FIT_INLINE double rms_misfit(double btb, const Vector<N>& c, const Vector<N>& atb, int rows) {
  return rms_misfit<N, double>(btb, c, atb, static_cast<double>(rows));
}

/// The shape operator [a b; b c] of a graph with Hessian `hessian` and gradient p at the
/// point, symmetrised in the metric G = I + p p^T: G^(-1/2) II G^(-1/2) with
/// II = -hessian / sqrt(1 + |p|^2). Its eigenvalues are the principal curvatures; its
/// eigenvectors are the directions in the plane to first order in p.
inline Eigen::Vector3d graph_operator(const Eigen::Matrix2d& hessian, const Eigen::Vector2d& p) {
  const double q = p.squaredNorm();
  const double root = std::sqrt(1.0 + q);
  Eigen::Matrix2d half = Eigen::Matrix2d::Identity();  // G^(-1/2)
  if (q > 0.0) half += (1.0 / root - 1.0) * p * p.transpose() / q;
  const Eigen::Matrix2d S = half * (-hessian / root) * half;
  return {S(0, 0), 0.5 * (S(0, 1) + S(1, 0)), S(1, 1)};
}

/// The lanes of a lane type L.
template <class L>
constexpr auto lanes_in = static_cast<std::size_t>(lane_count<L>);

/// Vertices fitted a vertex a lane, with their `Points` (a fit's points in the vertex's frame,
/// `size` of them). Each lane sums its own points in its stencil's order, then points that add
/// exact zeros up to the batch's longest stencil, so that it has the bits of its vertex fitted
/// alone. (Arrays of the language, not std::array: GCC folds identical element accessors of
/// arrays of different lengths into one and then reports the lanes' accesses against the
/// other's bounds.)
template <class Points, std::size_t width>
struct LaneBatch {
  std::size_t size = 0;  ///< lanes filled, below width between flushes
  /// size, shown to the compiler to be at most width.
  [[nodiscard]] std::size_t filled() const { return std::min(size, width); }
  std::int64_t row[width] = {};
  TangentFrame frame[width];
  Points points[width];

  /// Each lane's points from its own end up to the longest stencil set by pad(points, k) (to
  /// points that add exact zeros), the lanes not filled from the first; returns that length.
  template <class Pad>
  FOCAL_FIT_INLINE std::size_t pad_to_longest(Pad&& pad) {
    std::size_t longest = 0;
    for (std::size_t l = 0; l < filled(); ++l) longest = std::max(longest, points[l].size);
    for (std::size_t l = 0; l < width; ++l) {
      if (l >= filled()) points[l].size = 0;
      for (std::size_t k = points[l].size; k < longest; ++k) pad(points[l], k);
    }
    return longest;
  }
};

/// value(points) of each lane of `batch`, as a vector.
template <class L, class Points, class Value>
FOCAL_LANE_INLINE L lane_values(const LaneBatch<Points, lanes_in<L>>& batch, Value&& value) {
  return lanes_of<L>(
      [&](int l) FOCAL_FIT_LAMBDA { return value(batch.points[static_cast<std::size_t>(l)]); });
}

/// Whether v's 1-ring is closed: as many faces as neighbours in `incidence`.
inline bool closed_ring(const Neighbourhoods& one_ring, const VertexFaces& incidence, int v) {
  return incidence.size(v) == static_cast<int>(one_ring.end(v) - one_ring.begin(v));
}

/// What both fits read (prefer_hermite_fit's and prefer_height_fit's arguments).
struct FitInputs {
  PositionsRef V;
  const RowMatrixX3d& N;
  const std::vector<char>&ok, &keep, &moved;
  const Neighbourhoods& one_ring;
  const VertexFaces& incidence;
  double exact_residual;
  const ClassTolerances& tol;
};

/// Whether a fit takes vertex i at all: its normal is `ok`, it is not to be kept (`keep`, empty
/// or #V flags), its row's residual is not at most `exact_residual` (the two-slit fit is exact
/// there already; a NaN residual is fitted) and its 1-ring is closed.
inline bool takes_vertex(const FitInputs& in, const CurvatureResult& fit, std::int64_t i) {
  const auto v = static_cast<std::size_t>(i);
  return in.ok[v] && (in.keep.empty() || !in.keep[v]) && !(fit.residual[i] <= in.exact_residual) &&
         closed_ring(in.one_ring, in.incidence, static_cast<int>(i));
}

/// 1-rings up to this size gather their 2-ring by searching the entries found (ring_stencil).
constexpr std::size_t kSearchedRing = 16;

/// The 1-ring of v, or with `wide` its 2-ring (without v), less the `moved` vertices (empty or
/// #V flags), into `out` (the 1-ring in its order, the 2-ring ascending).
inline void ring_stencil(const Neighbourhoods& one_ring, int v, bool wide,
                         const std::vector<char>& moved, std::vector<int>& out) {
  out.assign(one_ring.begin(v), one_ring.end(v));
  if (wide) {
    const std::size_t first = out.size();
    // Each vertex once. About 18 of the 36 entries of a typical 1-ring's rings are new: a
    // linear search over those found is cheaper than sorting all 36; a wide fan's rings are
    // sorted instead (the search would be quadratic in its size).
    const bool search = first <= kSearchedRing;
    for (std::size_t k = 0; k < first; ++k) {
      for (const int* j = one_ring.begin(out[k]); j != one_ring.end(out[k]); ++j) {
        if (*j != v && (!search || std::find(out.begin(), out.end(), *j) == out.end()))
          out.push_back(*j);
      }
    }
    if (search) {
      sort_small(out.data(), out.data() + out.size(), std::less<>());
    } else {
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
    }
  }
  if (!moved.empty()) {
    std::erase_if(out, [&](int j) { return moved[static_cast<std::size_t>(j)] != 0; });
  }
}

}  // namespace focal::detail::polynomial
