#pragma once
// Internal: the sides of a sharp crease around a point (smoothing/creases.cpp) for
// smoothing/smooth.cpp: its neighbours grouped by their normals, and the point on the tangent
// planes of several sides.

#include <Eigen/Core>
#include <vector>

#include "focal/core/mesh.h"
#include "smoothing/surface_fit.h"

namespace focal::detail::smoothing {

/// At most this many sides meet at a point (a cube's corner: 3).
inline constexpr int kMaxSides = 3;
/// Members of a side for a fit of it: a plane (3 coefficients) with a margin for rejected
/// points. A cube's corner has about 6 to 10 on each face within 4 rings.
inline constexpr int kMinSidePoints = 5;
/// Members for a side's fit of the requested degree (a quadric has 6 coefficients); fewer give
/// a plane.
inline constexpr int kCurvedSidePoints = 10;

/// The degree of a side's fit with `members` points.
inline int side_degree(std::size_t members, int degree) {
  return members >= static_cast<std::size_t>(kCurvedSidePoints) ? degree : 1;
}

/// The sides around point i: the normals (rows of `frames`, unit or NaN) of its neighbours
/// `ring` (i itself left out) in up to kMaxSides groups, seeded at the densest directions and
/// refined by Lloyd rounds, each group's mean more than the crease angle (`cos_crease`, its cosine)
/// from the others' and with at least kMinSidePoints members; a normal more than half the crease
/// angle from its group's mean (a point of the crease itself) is in none, and a group left with
/// fewer than kMinSidePoints is dropped. Not `oriented` (cloud normals, lines): each normal first
/// turned to n_i's side. Returns the number of sides (0: no crease, or no side with enough members;
/// 1: one side of a crease, the others too small), their members in `side` (sorted) and their mean
/// normals in `mean`.
int crease_sides(const RowMatrixX3d& frames, int i, const std::vector<int>& ring, double cos_crease,
                 bool oriented, std::vector<int> (&side)[kMaxSides],
                 Eigen::Vector3d (&mean)[kMaxSides], std::vector<Eigen::Vector3d>& scratch);

/// Cloud points: a point lies on each side that one of its this many nearest neighbours is a
/// member of (a mesh vertex: each side its 1-ring meets).
inline constexpr int kSideNeighbours = 6;

/// The point nearest `p` on the tangent planes of the `count` surfaces (at their points, with
/// their normals): on the crease line of two sides, at the corner of three (least squares where
/// the planes do not meet in one point).
Eigen::Vector3d onto_planes(const Eigen::Vector3d& p, const LocalSurface* const* surfaces,
                            int count);

}  // namespace focal::detail::smoothing
