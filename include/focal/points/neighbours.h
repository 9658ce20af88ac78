#pragma once
/// \file neighbours.h
/// Neighbourhoods of point clouds: the k nearest neighbours or the neighbours within a radius of
/// every point, from a kd-tree (nanoflann), as the same CSR lists (mesh/neighbourhood.h) that
/// mesh k-rings are, so that everything after "neighbourhoods" is shared by meshes and clouds.
///
/// Each list is sorted by distance, ties broken by the smaller index, and never holds the point
/// itself. Points with a NaN or infinite coordinate are left out of the tree: their lists are
/// empty and they are in no list. Queries run in parallel and gather per point: the lists do not
/// depend on the thread count (that of the current ExecutionScope, focal/core/execution.h).
///
/// A kNN neighbourhood adapts to the local density by itself (its radius is the distance to the
/// k-th neighbour, about sqrt(k / (pi rho)) at density rho), which is why focal's cloud estimators
/// default to kNN rather than to a fixed radius (docs/POINTS.md).
#include <vector>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"

namespace focal {

/// The k nearest other points of every point (fewer where the cloud has fewer than k + 1 finite
/// points). Exactly equal positions (duplicates) are neighbours at distance 0.
/// \throw InvalidInput when k < 1 or the lists would not fit 32-bit offsets.
[[nodiscard]] Neighbourhoods nearest_neighbours(PositionsRef V, int k);

/// The same, leaving out the points flagged in `excluded` (#V flags, or empty for none) as
/// non-finite ones are: their lists are empty and they are in no list.
/// \throw InvalidInput as above, or when `excluded` is neither empty nor #V long.
[[nodiscard]] Neighbourhoods nearest_neighbours(PositionsRef V, int k,
                                                const std::vector<char>& excluded);

/// Every other point within Euclidean distance `radius` (inclusive), at most `max_count` of them
/// (the nearest; 0 = no limit).
/// \throw InvalidInput when radius is not finite and positive, max_count < 0 or the
/// lists would not fit 32-bit offsets.
[[nodiscard]] Neighbourhoods radius_neighbours(PositionsRef V, double radius, int max_count = 0);

/// The same, leaving out the points flagged in `excluded` (as nearest_neighbours).
[[nodiscard]] Neighbourhoods radius_neighbours(PositionsRef V, double radius, int max_count,
                                               const std::vector<char>& excluded);

/// Neighbourhoods whose radius follows the local density: point i gets every other point within
/// scale x r_i (inclusive, at most `max_count`, the nearest; 0 = no limit), r_i the median, over
/// i and its k nearest, of their distances to their own k-th nearest (smoothed, so that one
/// sparse or dense spot does not set a radius of its own). Flags in `excluded` as
/// nearest_neighbours. Lists sorted by (distance, index): identical for any thread count.
/// \throw InvalidInput when k < 1, scale is not finite and > 0, or max_count < 0.
[[nodiscard]] Neighbourhoods adaptive_radius_neighbours(PositionsRef V, int k, double scale,
                                                        int max_count,
                                                        const std::vector<char>& excluded = {});

/// Statistical outliers (#V flags): points whose mean distance to their neighbours is more than
/// `ratio` times the median of their neighbours' own mean distances. Measured against the
/// neighbours rather than the whole cloud (as PCL's and Open3D's statistical outlier removal
/// are), so that a cloud whose density varies (a scan sparser far from the scanner) loses no
/// point for being in its sparse part: an isolated point off the surface is far from its
/// neighbours, which are close to theirs. Points with an empty list are not flagged.
/// \throw InvalidInput when ratio is not finite and > 1, or the neighbourhoods are not V's.
[[nodiscard]] std::vector<char> outlier_points(PositionsRef V, const Neighbourhoods& neighbours,
                                               double ratio);

/// Points off their neighbours' surface (#V flags): the distance of a point to the
/// least-squares plane of its neighbours (the point itself not in the fit) is more than `ratio`
/// times the RMS distance of those neighbours to that plane (the sampling noise plus the
/// surface's bending over the neighbourhood). The point being in neither, an outlier does not
/// raise its own yardstick; another outlier among its neighbours raises it (the test errs
/// towards keeping points). A point so flagged is kept again when its distance is at most
/// ratio / 2 times the median over its neighbours of their own distance to their neighbours'
/// plane, the point left out of those: a regular sampling (the pole of a sphere sampled in
/// rings has one ring as its nearest, spread ~0). It catches what outlier_points does not: a
/// point a spacing or more off the surface, as close to its neighbours as they are to theirs;
/// not a point off the surface's edge within its tangent plane. Points with fewer than 3
/// neighbours are not flagged; an RMS below 1e-9 x the mean neighbour distance counts as that
/// (exactly flat neighbourhoods).
/// \throw InvalidInput when ratio is not finite and > 1, or the neighbourhoods are not V's.
[[nodiscard]] std::vector<char> off_surface_points(PositionsRef V, const Neighbourhoods& neighbours,
                                                   double ratio);

/// The mean over finite points of the distance to their nearest other point (0 when no point
/// has a neighbour): the sampling spacing of a cloud, the scale of its class tolerances as the
/// mean edge length is a mesh's.
[[nodiscard]] double mean_spacing(PositionsRef V, const Neighbourhoods& neighbours);

}  // namespace focal
