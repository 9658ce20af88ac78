#pragma once
// Internal: an order of a mesh's or a cloud's rows that keeps near points near, for the tiles
// (tiles/tiles.cpp: consecutive runs of it) and for the work that reads neighbours' rows
// (points/neighbours.cpp: the kd-tree's build; curvature/cloud_curvature.cpp).

#include <vector>

#include "focal/core/mesh.h"

namespace focal::detail {

/// The rows of V in the order of their Morton (Z-order) codes over the box of the finite rows,
/// 21 bits per axis (a cell of 2^-21 of the box on each axis), ties by row; non-finite rows
/// last. Identical for any thread count.
std::vector<int> morton_order(PositionsRef V, int threads);

}  // namespace focal::detail
