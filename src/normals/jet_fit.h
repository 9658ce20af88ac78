#pragma once
// Internal: the fit of a jet's height polynomial (normals/jet_fit.cpp) for normals/jets.cpp. A
// vertex's points in its tangent frame give the moments of the normal equations; the fits of
// several vertices run side by side in the lanes of a SIMD kernel, one per instruction set, and
// each lane's result has the bits of the scalar path (the kernel without lanes).

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <vector>

#include "core/simd_lanes.h"
#include "kernels/local_shape.h"

namespace focal::detail::jets {

constexpr int kMaxDegree = 4;

constexpr int coefficient_count(int degree) { return (degree + 1) * (degree + 2) / 2; }

constexpr int kMaxCoefficients = coefficient_count(kMaxDegree);

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

/// The lane kernel of one degree: moments and the degree-D fit of every lane of a batch.
using TopDegreeKernel = void (*)(JetBatch&);

/// The kernel of fits of `degree` (1 to kMaxDegree) for `isa`'s lanes; std::nullopt: the scalar
/// path, one vertex at a time.
TopDegreeKernel top_degree_kernel(std::optional<SimdIsa> isa, int degree);

/// The degree-`degree` fit of a scalar batch (the kernel without lanes) from its moments b.xy,
/// b.z as they stand into b.c: a caller that downdated them (a point taken out of the sums) gets
/// the fit without that point, with the bits of a fit to the remaining points. False when the
/// system is not well posed or `count` (the points the moments sum) is below
/// coefficient_count(degree).
bool solve_moments(int degree, JetBatch& b, int count);

/// The kernel's lane count: 1 without lanes.
int batch_width(std::optional<SimdIsa> isa);

/// The jet's residual from the squared residuals of its fit of m coefficients to n points.
double residual_of(double ssr, int n, int m, double scale);

/// The fit of the highest degree < D that succeeds, one lane alone, where degree D failed in
/// its batch: the scalar path (moments and degree D again, the same bits, then lower degrees).
/// `scalar` and `scalar_terms` are the caller's scratch for that path (reused across calls).
bool fit_lower_degrees(int degree, const Point* points, int n, JetBatch& scalar,
                       std::vector<double>& scalar_terms, LocalJet& jet);

}  // namespace focal::detail::jets
