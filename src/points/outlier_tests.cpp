// The outlier tests of points/neighbours.h: points far from their neighbours (outlier_points)
// and points off their neighbours' plane (off_surface_points), from a cloud's lists or from the
// measures the kNN query took of them (measured_neighbours.h).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/points/neighbours.h"
#include "points/argument_checks.h"
#include "points/measured_neighbours.h"
#include "points/plane_sums.h"

namespace focal {
namespace {

using detail::check_threads;
using detail::PlaneSums;

void check_ratio(const char* test, double ratio) {
  if (!(ratio > 1.0) || !std::isfinite(ratio)) {
    throw InvalidInput(std::string(test) + ": ratio must be finite and > 1, got " +
                       std::to_string(ratio));
  }
}

void check_lists(const char* test, PositionsRef V, const Neighbourhoods& neighbours) {
  if (neighbours.vertex_count() != V.rows()) {
    throw InvalidInput(std::string(test) + ": the neighbourhoods are not V's");
  }
}

}  // namespace

std::vector<char> outlier_points(PositionsRef V, const Neighbourhoods& neighbours, double ratio) {
  check_ratio("outlier_points", ratio);
  check_lists("outlier_points", V, neighbours);
  const int n = neighbours.vertex_count();
  std::vector<double> reach(static_cast<std::size_t>(n), NAN);
  detail::parallel_for(n, 0, [&](std::int64_t i) {
    const int p = static_cast<int>(i);
    if (neighbours.size(p) == 0) return;
    double sum = 0.0;
    for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
      sum += (V.row(*j) - V.row(p)).norm();
    }
    reach[static_cast<std::size_t>(i)] = sum / neighbours.size(p);
  });
  return detail::outlier_points(V, neighbours, reach, ratio, 0);
}

std::vector<char> detail::outlier_points(PositionsRef V, const Neighbourhoods& neighbours,
                                         const std::vector<double>& reach, double ratio,
                                         int threads) {
  check_ratio("outlier_points", ratio);
  check_threads(threads);
  check_lists("outlier_points", V, neighbours);
  const int n = neighbours.vertex_count();
  if (reach.size() != static_cast<std::size_t>(n)) {
    throw InvalidInput("outlier_points: the measures are not the neighbourhoods'");
  }
  std::vector<char> outlier(static_cast<std::size_t>(n), 0);
  // r > ratio x (the median m of the neighbours' finite reaches, element size / 2 of them
  // sorted) without the median: x -> ratio * x is monotone in floating point too, so the test
  // holds exactly when more than size / 2 of them have ratio * reach < r (then the sorted
  // elements 0 .. size / 2 do, m among them; and conversely). The same flags as an nth_element
  // per point.
  detail::parallel_for(n, threads, [&](std::int64_t i) {
    const int p = static_cast<int>(i);
    const double r = reach[static_cast<std::size_t>(i)];
    int finite = 0, below = 0;
    for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
      const double a = reach[static_cast<std::size_t>(*j)];
      if (!std::isfinite(a)) continue;
      ++finite;
      below += r > ratio * a;
    }
    outlier[static_cast<std::size_t>(i)] = finite > 0 && below > finite / 2;
  });
  return outlier;
}

namespace {

/// A point's PlaneOffset over its neighbours, leaving out `without` (-1: none).
detail::PlaneOffset plane_offset(PositionsRef V, const Neighbourhoods& neighbours, int p,
                                 int without) {
  const Eigen::RowVector3d origin = V.row(p);
  PlaneSums plane;
  for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
    if (*j == without) continue;
    const Eigen::RowVector3d q = V.row(*j) - origin;
    plane.add(q);
  }
  if (!origin.allFinite()) return {};
  return plane.offset();
}

/// The median over the neighbours of p of their plane_offset distance without p: how far a
/// point on this sampling sits off its neighbours' plane, p not counted (NaN when none has one).
double neighbours_offset_without(PositionsRef V, const Neighbourhoods& neighbours, int p,
                                 std::vector<double>& around) {
  around.clear();
  for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
    const double d = plane_offset(V, neighbours, *j, p).distance;
    if (std::isfinite(d)) around.push_back(d);
  }
  if (around.empty()) return NAN;
  const auto middle = around.begin() + static_cast<std::ptrdiff_t>(around.size() / 2);
  std::nth_element(around.begin(), middle, around.end());
  return *middle;
}

/// off_surface_points with each point's own PlaneOffset from offset_of(p).
template <class OffsetOf>
std::vector<char> off_surface(PositionsRef V, const Neighbourhoods& neighbours, double ratio,
                              int threads, const OffsetOf& offset_of) {
  std::vector<char> off(static_cast<std::size_t>(neighbours.vertex_count()), 0);
  detail::parallel_for_blocks(
      neighbours.vertex_count(), 1024, threads, [&](std::int64_t begin, std::int64_t end) {
        std::vector<double> around;
        for (std::int64_t i = begin; i < end; ++i) {
          const int p = static_cast<int>(i);
          const detail::PlaneOffset o = offset_of(p);
          if (!(o.distance > ratio * o.spread)) continue;
          // A candidate (rare): kept when its neighbours, each without it, sit nearly as far off
          // their own neighbours' planes: a regular sampling, such as the pole of a sphere
          // sampled in rings, whose 16 nearest are one ring (spread ~0) with the pole its
          // sagitta above. Half the ratio: the poles of CGAL's sphere926.pwn sit 2-3 times their
          // neighbours' offset; the near-surface outliers of the analytic clouds far more (none
          // kept by it).
          const double typical = neighbours_offset_without(V, neighbours, p, around);
          off[static_cast<std::size_t>(i)] = !(o.distance <= 0.5 * ratio * typical);
        }
      });
  return off;
}

}  // namespace

std::vector<char> off_surface_points(PositionsRef V, const Neighbourhoods& neighbours,
                                     double ratio) {
  check_ratio("off_surface_points", ratio);
  check_lists("off_surface_points", V, neighbours);
  return off_surface(V, neighbours, ratio, 0,
                     [&](int p) { return plane_offset(V, neighbours, p, -1); });
}

std::vector<char> detail::off_surface_points(PositionsRef V, const Neighbourhoods& neighbours,
                                             const OutlierMeasures& measures, double ratio,
                                             int threads) {
  check_ratio("off_surface_points", ratio);
  check_threads(threads);
  check_lists("off_surface_points", V, neighbours);
  const auto n = static_cast<std::size_t>(neighbours.vertex_count());
  if (measures.distance.size() != n || measures.spread.size() != n) {
    throw InvalidInput("off_surface_points: the measures are not the neighbourhoods'");
  }
  return off_surface(V, neighbours, ratio, threads, [&](int p) {
    const auto i = static_cast<std::size_t>(p);
    return PlaneOffset{measures.distance[i], measures.spread[i]};
  });
}

}  // namespace focal
