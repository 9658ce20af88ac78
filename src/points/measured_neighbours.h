#pragma once
// Internal: the kNN query and the outlier tests of points/neighbours.h in one pass, for the cloud
// estimators (curvature/cloud_curvature.cpp). The query has just read each neighbour's position
// (the tree's leaf-ordered copy, in cache); the tests over V's rows read them again, scattered
// over all of V on a randomly ordered cloud.

#include <cmath>
#include <vector>

#include "core/spatial_order.h"
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
  Neighbourhoods neighbours;  ///< nearest_neighbours(V, k, excluded), the same lists
  OutlierMeasures measures;
};

/// nearest_neighbours(V, k, excluded) of a cloud whose rows were permuted: ties ordered
/// by tie_rows[row] (#V: each row's index before the permutation) instead of by row, so that
/// every list is, entry by entry, the permuted cloud's image of the list its point gets in the
/// cloud's own order. Empty: by row (nearest_neighbours itself). With tie rows, V is taken to be
/// in a spatial order already (detail::morton_permutation's copy): the kd-tree takes its rows as
/// they come instead of sorting them (the lists do not depend on the tree's shape).
/// \throw InvalidInput as nearest_neighbours, or when tie_rows is neither empty nor #V long.
Neighbourhoods nearest_neighbours(PositionsRef V, int k, const std::vector<char>& excluded,
                                  int threads, const std::vector<int>& tie_rows);

/// detail::nearest_neighbours(V, k, excluded, threads, tie_rows) and the outlier tests' measures
/// of its lists, in the same pass. Identical for any thread count.
MeasuredNeighbours measured_nearest_neighbours(PositionsRef V, int k,
                                               const std::vector<char>& excluded, int threads,
                                               const std::vector<int>& tie_rows = {});

/// outlier_points(V, neighbours, ratio) from `reach`, the measures of those lists.
std::vector<char> outlier_points(PositionsRef V, const Neighbourhoods& neighbours,
                                 const std::vector<double>& reach, double ratio, int threads);

/// off_surface_points(V, neighbours, ratio) from `measures` of those lists.
std::vector<char> off_surface_points(PositionsRef V, const Neighbourhoods& neighbours,
                                     const OutlierMeasures& measures, double ratio, int threads);

/// mean_spacing(V, neighbours) on `threads` threads (the same value for any count), its sum
/// taken in the order of `tie_rows` (as above: the rows before a permutation; empty: by row), so
/// a permuted cloud gets the bits of the cloud in its own order.
double mean_spacing(PositionsRef V, const Neighbourhoods& neighbours, int threads,
                    const std::vector<int>& tie_rows = {});

/// The lists of a permuted copy of a cloud (copy row j is cloud row p.order[j]) in the cloud's
/// own rows: row i's list is the copy's list of its row p.position[i], each entry j renamed
/// p.order[j], in the same order.
Neighbourhoods unpermuted_neighbours(const Neighbourhoods& copy, const RowPermutation& p,
                                     int threads);

}  // namespace focal::detail
