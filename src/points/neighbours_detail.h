#pragma once
// Internal: the kNN query and the outlier tests of points/neighbours.h in one pass, for the cloud
// estimators (curvature/cloud_curvature.cpp). The query has just read each neighbour's position
// (the tree's leaf-ordered copy, in cache); the tests over V's rows read them again, scattered
// over all of V on a randomly ordered cloud. Measured on the 997,026-point torus of
// docs/POINTS.md ("Speed and memory"): the same tests over a spatially sorted copy of it took
// 0.7-0.9 s instead of 1.0-1.4 s on one thread.

#include <cmath>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"

namespace focal::detail {

/// A point's distance to the least-squares plane of its neighbours and the RMS distance of those
/// neighbours to that plane (off_surface_points); NaN when fewer than 3 or the plane is undefined.
struct PlaneOffset {
  double distance = NAN;
  double spread = NAN;
};

/// Per point (#V each), over its list: what outlier_points and off_surface_points compute
/// before they compare, bit for bit. NaN where a point has no list (or too short a one).
struct OutlierMeasures {
  std::vector<double> reach;             ///< mean distance to the neighbours
  std::vector<double> distance, spread;  ///< its PlaneOffset
};

struct MeasuredNeighbours {
  Neighbourhoods neighbours;  ///< nearest_neighbours(V, k, excluded, threads), the same lists
  OutlierMeasures measures;
};

/// nearest_neighbours(V, k, excluded, threads) and the outlier tests' measures of its lists, in
/// the same pass. Identical for any thread count.
MeasuredNeighbours measured_nearest_neighbours(PositionsRef V, int k,
                                               const std::vector<char>& excluded, int threads);

/// outlier_points(V, neighbours, ratio, threads) from `reach`, the measures of those lists.
std::vector<char> outlier_points(PositionsRef V, const Neighbourhoods& neighbours,
                                 const std::vector<double>& reach, double ratio, int threads);

/// off_surface_points(V, neighbours, ratio, threads) from `measures` of those lists.
std::vector<char> off_surface_points(PositionsRef V, const Neighbourhoods& neighbours,
                                     const OutlierMeasures& measures, double ratio, int threads);

/// mean_spacing(V, neighbours) on `threads` threads (the same value for any count).
double mean_spacing(PositionsRef V, const Neighbourhoods& neighbours, int threads);

}  // namespace focal::detail
