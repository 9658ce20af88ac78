#pragma once
// Internal: Delaunay triangulation of points in the plane, used by
// surfaces/irregular_triangulation.cpp to triangulate random samples in a planar parameter chart. Bowyer-Watson insertion with a vertex at infinity
// (Shewchuk's ghost triangles), so the convex hull comes out exactly and a triangulated sphere
// is one fan away: closing every hull edge with one extra vertex gives the Delaunay
// triangulation on the sphere when the points are a stereographic projection.

#include <Eigen/Core>
#include <array>
#include <vector>

namespace focal::detail {

struct PlanarDelaunay {
  /// Finite triangles, counter-clockwise, as indices into the input points.
  std::vector<std::array<int, 3>> triangles;
  /// Convex hull edges (a, b) directed clockwise around the hull: the triangle with b -> a lies
  /// inside, so (a, b, x) is consistently oriented for a vertex x "at infinity".
  std::vector<std::array<int, 2>> hull_edges;
};

/// Delaunay triangulation of `points`. Floating-point predicates; a cavity that rounding makes
/// non-star-shaped is shrunk until it is, so the result is always a valid triangulation of the
/// convex hull (Delaunay up to rounding in near-cocircular configurations).
/// \throw InvalidInput for fewer than 3 points, all points collinear, a non-finite coordinate or
/// a duplicate point.
[[nodiscard]] PlanarDelaunay planar_delaunay(const std::vector<Eigen::Vector2d>& points);

}  // namespace focal::detail
