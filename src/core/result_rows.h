#pragma once
// Writing a CurvatureResult (core/fields.h) row by row, for every estimator that fills one:
// allocation without a fill, and the `undefined` row.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "core/parallel.h"
#include "focal/core/fields.h"

namespace focal::detail {

/// A result of n vertices with every field allocated but not written: the caller writes each
/// row once, with store_vertex or store_undefined, from the thread that owns it (first touch
/// then happens in parallel, and nothing is written twice).
inline CurvatureResult unwritten_result(Eigen::Index n) {
  CurvatureResult r;
  for (Eigen::VectorXd* v : {&r.k1, &r.k2, &r.H, &r.K, &r.residual}) v->resize(n);
  r.d1.resize(n, 3);
  r.d2.resize(n, 3);
  r.point_class.resize(n);
  r.rays_used.resize(n);
  r.rays_excluded.resize(n);
  for (Eigen::VectorXd* v : {&r.k1, &r.k2, &r.H, &r.K, &r.residual}) {
    advise_huge_pages(v->data(), sizeof(double) * static_cast<std::size_t>(n));
  }
  for (RowMatrixX3d* d : {&r.d1, &r.d2}) {
    advise_huge_pages(d->data(), 3 * sizeof(double) * static_cast<std::size_t>(n));
  }
  return r;
}

/// Copies row `from_row` of every field of `from` into row `to_row` of `to`.
inline void copy_row(const CurvatureResult& from, Eigen::Index from_row, CurvatureResult& to,
                     Eigen::Index to_row) {
  for (auto field : {&CurvatureResult::k1, &CurvatureResult::k2, &CurvatureResult::H,
                     &CurvatureResult::K, &CurvatureResult::residual}) {
    (to.*field)[to_row] = (from.*field)[from_row];
  }
  to.d1.row(to_row) = from.d1.row(from_row);
  to.d2.row(to_row) = from.d2.row(from_row);
  to.point_class[to_row] = from.point_class[from_row];
  to.rays_used[to_row] = from.rays_used[from_row];
  to.rays_excluded[to_row] = from.rays_excluded[from_row];
}

/// Marks vertex i `undefined`: NaN in every numeric field. Leaves the ray counts alone.
inline void store_undefined(CurvatureResult& r, Eigen::Index i) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.k1[i] = r.k2[i] = r.H[i] = r.K[i] = r.residual[i] = nan;
  r.d1.row(i).setConstant(nan);
  r.d2.row(i).setConstant(nan);
  r.point_class[i] = static_cast<std::uint8_t>(PointClass::undefined);
}

/// A result of n vertices, every one `undefined` with NaN fields until it is filled.
inline CurvatureResult undefined_result(Eigen::Index n, int threads = 0) {
  CurvatureResult r = unwritten_result(n);
  parallel_for(n, threads, [&](std::int64_t i) {
    store_undefined(r, i);
    r.rays_used[i] = r.rays_excluded[i] = 0;
  });
  return r;
}

}  // namespace focal::detail
