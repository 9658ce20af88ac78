#pragma once
// Internal: the kd-tree of the neighbourhood queries (points/neighbours.cpp): nanoflann's tree
// over a cloud's finite points, built in parallel with nanoflann's splits (point_tree.cpp), its
// copies of the points in the tree's leaf order.

#include <cmath>
#include <cstdint>
#include <deque>
#include <memory>
#include <nanoflann.hpp>
#include <utility>
#include <vector>

#include "focal/core/mesh.h"

namespace focal::detail {

/// (squared distance, row): ordered by distance, then index, so that ties do not depend on the
/// tree's traversal.
using Candidate = std::pair<double, int>;

/// The finite rows of V copied into one contiguous array, as nanoflann's dataset adaptor reads
/// them. After the tree is built they are permuted into the tree's leaf order (PointTree), so a
/// leaf's points are adjacent in memory and tree index j is simply the j-th point.
struct FinitePoints {
  std::vector<double> xyz;  ///< 3 per point
  std::vector<int> rows;    ///< tree index -> row of V

  [[nodiscard]] std::size_t kdtree_get_point_count() const { return rows.size(); }
  [[nodiscard]] double kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return xyz[3 * i + dim];
  }
  [[nodiscard]] const double* point(std::size_t i) const { return xyz.data() + 3 * i; }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, FinitePoints>,
                                                 FinitePoints, 3, std::uint32_t>;

/// A tree over the finite points of V, their copies stored in the tree's leaf order. Queries
/// made in that order (tree index 0, 1, ...) walk the leaves their neighbours walked, which stay
/// in cache, and read the points contiguously. Leaves hold at most 16 points; the lists the
/// queries give do not depend on the tree's shape.
class PointTree {
 public:
  /// `excluded`: empty, or #V flags of points to leave out as the non-finite ones are.
  /// `spatial`: V's rows are in a spatial order already (a copy of a cloud in Morton order), so
  /// they are taken as they come.
  PointTree(PositionsRef V, const std::vector<char>& excluded, int threads, bool spatial = false);
  [[nodiscard]] const Tree& tree() const { return *tree_; }
  [[nodiscard]] int row(std::uint32_t index) const { return points_.rows[index]; }
  [[nodiscard]] std::size_t size() const { return points_.rows.size(); }
  [[nodiscard]] const double* point(std::size_t index) const { return points_.point(index); }

  /// Every point at squared distance <= d2 from q (nanoflann's radius test is strict: d2 is
  /// raised to the next double), appended to `out`.
  void within(const double* q, double d2, std::vector<Candidate>& out) const {
    within(q, d2,
           [&](double distance, std::uint32_t index) { out.emplace_back(distance, row(index)); });
  }
  /// The same, each as emit(squared distance, tree index).
  template <class Emit>
  void within(const double* q, double d2, const Emit& emit) const {
    std::vector<std::pair<std::uint32_t, double>> matches;
    nanoflann::SearchParams params;
    params.sorted = false;
    tree_->radiusSearch(q, std::nextafter(d2, INFINITY), matches, params);
    for (const auto& [index, distance] : matches) {
      if (distance <= d2) emit(distance, index);
    }
  }

 private:
  using Node = Tree::Node;
  using Box = Tree::BoundingBox;

  /// A subtree still to build: points [left, right) of the index array, the box its splits
  /// start from, where its root goes.
  struct Pending {
    std::size_t left, right;
    Box box;
    Node** slot;
    Box* built;  ///< the box of its points, set when built
  };

  /// nanoflann's buildIndex (the same splits: middleSplit_, leaves of at most 16 points, so the
  /// same tree), the top kLevels levels one level at a time and the subtrees below them in
  /// parallel, each into nodes of its own (nanoflann's node pool is not thread-safe). Splits
  /// depend on the points and the boxes handed down only, so the tree is the same for any
  /// thread count.
  void build(int threads);

  /// nanoflann's divideTree, its nodes from `nodes`.
  Node* divide(std::deque<Node>& nodes, std::size_t left, std::size_t right, Box& box);

  /// The points permuted so that the tree's index array becomes the identity: the tree (split
  /// values, bounding boxes, index ranges of the leaves) is unchanged, its point j is now ours.
  void to_leaf_order(int threads);

  FinitePoints points_;
  std::unique_ptr<Tree> tree_;
  std::deque<Node> top_;                 ///< the nodes of the top levels
  std::vector<std::deque<Node>> nodes_;  ///< each subtree's
};

}  // namespace focal::detail
