#pragma once
// Internal: an order of a mesh's or a cloud's rows that keeps near points near, for the tiles
// (tiles/tiles.cpp: consecutive runs of it) and for the work that reads neighbours' rows
// (points/point_tree.cpp: the kd-tree's build; curvature/cloud_curvature.cpp), and copies of
// rows in such an order (curvature/cloud_curvature.cpp: a cloud's whole fit on a copy).

#include <cstdint>
#include <vector>

#include "core/parallel.h"
#include "focal/core/mesh.h"

namespace focal::detail {

/// The rows of V in the order of their Morton (Z-order) codes over the box of the finite rows,
/// `bits_per_axis` bits per axis (1 to 21: a cell of 2^-bits of the box on each axis), ties by
/// row; non-finite rows last. Identical for any thread count.
std::vector<int> morton_order(PositionsRef V, int threads, int bits_per_axis = 21);

/// A permutation of V's rows and its inverse: row j of a copy is row order[j] of V, and row i of
/// V is row position[i] of the copy.
struct RowPermutation {
  std::vector<int> order;
  std::vector<int> position;
};

/// Bits per axis of morton_permutation: cells of 2^-10 of the box, 2^30 of them, far more than
/// the points of any cloud whose reads they are to keep near (1M points on a torus: a cell holds
/// one or none), sorted in two passes of morton_order's counting sort instead of four.
inline constexpr int kPermutationBits = 10;

/// morton_order(V, threads, kPermutationBits) and its inverse.
RowPermutation morton_permutation(PositionsRef V, int threads);

/// What work on a cloud's permuted copy needs of the cloud: the permutation (copy row j is row
/// permutation.order[j] of the cloud) and the cloud's positions in its own order.
struct CloudCopy {
  const RowPermutation& permutation;
  PositionsRef cloud;
};

/// The rows of M taken in the order `from`: row i of the result is row from[i] of M (a gather:
/// each output row written once, in parallel). A copy in a permutation's order takes
/// `order`; the copy's rows back in M's order take `position`.
template <class Derived>
typename Derived::PlainObject rows_from(const Eigen::MatrixBase<Derived>& M,
                                        const std::vector<int>& from, int threads) {
  using Matrix = typename Derived::PlainObject;
  const auto n = static_cast<std::int64_t>(from.size());
  Matrix out(n, M.cols());
  parallel_for(n, threads, [&](std::int64_t i) {
    const auto row = from[static_cast<std::size_t>(i)];
    if constexpr (Matrix::ColsAtCompileTime == 1) {
      out[i] = M[row];
    } else {
      out.row(i) = M.row(row);
    }
  });
  return out;
}

}  // namespace focal::detail
