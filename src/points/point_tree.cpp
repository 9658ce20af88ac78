// The kd-tree of the neighbourhood queries (point_tree.h): the points in a spatial order, the
// tree's top levels split one level at a time and the subtrees below them in parallel, then the
// points permuted into the leaves' order.
#include "points/point_tree.h"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "core/spatial_order.h"
#include "focal/core/error.h"

namespace focal::detail {

PointTree::PointTree(PositionsRef V, const std::vector<char>& excluded, int threads, bool spatial) {
  if (!excluded.empty() && excluded.size() != static_cast<std::size_t>(V.rows())) {
    throw InvalidInput("neighbours: " + std::to_string(excluded.size()) + " exclusion flags for " +
                       std::to_string(V.rows()) + " points");
  }
  points_.rows.reserve(static_cast<std::size_t>(V.rows()));
  // In a spatial order rather than by row: the build's partitions then move points that are
  // near in memory too. The lists do not depend on the tree's shape: they are the nearest by
  // distance, ties broken by row.
  const auto add = [&](int i) {
    const bool out = !excluded.empty() && excluded[static_cast<std::size_t>(i)] != 0;
    if (!out && V.row(i).allFinite()) points_.rows.push_back(i);
  };
  if (spatial) {
    for (int i = 0; i < V.rows(); ++i) add(i);
  } else {
    for (const int i : detail::morton_order(V, threads)) add(i);
  }
  points_.xyz.resize(3 * points_.rows.size());
  for (std::size_t j = 0; j < points_.rows.size(); ++j) {
    for (int d = 0; d < 3; ++d) points_.xyz[3 * j + d] = V(points_.rows[j], d);
  }
  tree_ = std::make_unique<Tree>(
      3, points_,
      nanoflann::KDTreeSingleIndexAdaptorParams(
          16, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex));
  build(threads);
  to_leaf_order(threads);
}

void PointTree::build(int threads) {
  Tree& t = *tree_;
  const std::size_t n = points_.rows.size();
  t.m_size = n;
  t.m_size_at_index_build = n;
  t.vAcc.resize(n);
  for (std::size_t i = 0; i < n; ++i) t.vAcc[i] = static_cast<std::uint32_t>(i);
  if (n == 0) return;
  Box box;
  for (int d = 0; d < 3; ++d) box[d].low = box[d].high = points_.xyz[static_cast<std::size_t>(d)];
  for (std::size_t i = 1; i < n; ++i) {
    for (int d = 0; d < 3; ++d) {
      const double x = points_.xyz[3 * i + static_cast<std::size_t>(d)];
      if (x < box[d].low) box[d].low = x;
      if (x > box[d].high) box[d].high = x;
    }
  }
  // The top levels, one level at a time: inner nodes whose boxes are finished bottom-up.
  struct Inner {
    Node* node = nullptr;  ///< null where the entry was a leaf already
    int cutfeat = 0;
    Box* built = nullptr;  ///< where its points' box goes
    Box left_box, right_box;
  };
  constexpr int kLevels = 8;  // up to 256 subtrees of about 4000 points at 1M
  std::vector<Pending> level{{0, n, box, &t.root_node, &t.root_bbox}};
  std::vector<std::vector<Inner>> inners;  // per level
  std::vector<Pending> subtrees;
  for (int depth = 0; depth < kLevels && !level.empty(); ++depth) {
    std::vector<Pending> next(2 * level.size());
    std::vector<Inner>& inner = inners.emplace_back(level.size());
    detail::parallel_chunks(static_cast<std::int64_t>(level.size()), threads, [&](std::int64_t c) {
      const auto j = static_cast<std::size_t>(c);
      const Pending& at = level[j];
      if (at.right - at.left <= t.m_leaf_max_size) return;
      std::size_t index = 0;
      int cutfeat = 0;
      double cutval = 0.0;
      t.middleSplit_(t, at.left, at.right - at.left, index, cutfeat, cutval, at.box);
      Inner& in = inner[j];
      in.cutfeat = cutfeat;
      in.left_box = in.right_box = at.box;
      in.left_box[cutfeat].high = cutval;
      in.right_box[cutfeat].low = cutval;
      next[2 * j] = {at.left, at.left + index, in.left_box, nullptr, &in.left_box};
      next[2 * j + 1] = {at.left + index, at.right, in.right_box, nullptr, &in.right_box};
    });
    std::vector<Pending> kept;
    for (std::size_t j = 0; j < level.size(); ++j) {
      if (level[j].right - level[j].left <= t.m_leaf_max_size) {
        subtrees.push_back(level[j]);  // a leaf already
        continue;
      }
      Inner& in = inner[j];
      in.node = &top_.emplace_back();
      in.built = level[j].built;
      *level[j].slot = in.node;
      next[2 * j].slot = &in.node->child1;
      next[2 * j + 1].slot = &in.node->child2;
      kept.push_back(next[2 * j]);
      kept.push_back(next[2 * j + 1]);
    }
    level.swap(kept);
  }
  subtrees.insert(subtrees.end(), level.begin(), level.end());
  nodes_.resize(subtrees.size());
  detail::parallel_chunks(static_cast<std::int64_t>(subtrees.size()), threads, [&](std::int64_t c) {
    const Pending& at = subtrees[static_cast<std::size_t>(c)];
    Box b = at.box;
    *at.slot = divide(nodes_[static_cast<std::size_t>(c)], at.left, at.right, b);
    *at.built = b;
  });
  // Bottom-up, as divideTree after its two recursive calls.
  for (auto at = inners.rbegin(); at != inners.rend(); ++at) {
    for (const Inner& in : *at) {
      if (in.node == nullptr) continue;
      in.node->node_type.sub.divfeat = in.cutfeat;
      in.node->node_type.sub.divlow = in.left_box[in.cutfeat].high;
      in.node->node_type.sub.divhigh = in.right_box[in.cutfeat].low;
      for (int d = 0; d < 3; ++d) {
        (*in.built)[d].low = std::min(in.left_box[d].low, in.right_box[d].low);
        (*in.built)[d].high = std::max(in.left_box[d].high, in.right_box[d].high);
      }
    }
  }
}

PointTree::Node* PointTree::divide(std::deque<Node>& nodes, std::size_t left, std::size_t right,
                                   Box& box) {
  Tree& t = *tree_;
  Node* node = &nodes.emplace_back();
  if (right - left <= t.m_leaf_max_size) {
    node->child1 = node->child2 = nullptr;
    node->node_type.lr.left = left;
    node->node_type.lr.right = right;
    for (int d = 0; d < 3; ++d) box[d].low = box[d].high = points_.xyz[3 * t.vAcc[left] + d];
    for (std::size_t k = left + 1; k < right; ++k) {
      for (int d = 0; d < 3; ++d) {
        const double x = points_.xyz[3 * t.vAcc[k] + d];
        if (box[d].low > x) box[d].low = x;
        if (box[d].high < x) box[d].high = x;
      }
    }
    return node;
  }
  std::size_t index = 0;
  int cutfeat = 0;
  double cutval = 0.0;
  t.middleSplit_(t, left, right - left, index, cutfeat, cutval, box);
  node->node_type.sub.divfeat = cutfeat;
  Box left_box(box);
  left_box[cutfeat].high = cutval;
  node->child1 = divide(nodes, left, left + index, left_box);
  Box right_box(box);
  right_box[cutfeat].low = cutval;
  node->child2 = divide(nodes, left + index, right, right_box);
  node->node_type.sub.divlow = left_box[cutfeat].high;
  node->node_type.sub.divhigh = right_box[cutfeat].low;
  for (int d = 0; d < 3; ++d) {
    box[d].low = std::min(left_box[d].low, right_box[d].low);
    box[d].high = std::max(left_box[d].high, right_box[d].high);
  }
  return node;
}

void PointTree::to_leaf_order(int threads) {
  std::vector<std::uint32_t>& order = tree_->vAcc;
  std::vector<double> xyz(points_.xyz.size());
  std::vector<int> rows(points_.rows.size());
  detail::parallel_for(static_cast<std::int64_t>(order.size()), threads, [&](std::int64_t i) {
    const auto j = static_cast<std::size_t>(i);
    std::copy_n(points_.point(order[j]), 3, xyz.data() + 3 * j);
    rows[j] = points_.rows[order[j]];
    order[j] = static_cast<std::uint32_t>(j);
  });
  points_.xyz.swap(xyz);
  points_.rows.swap(rows);
}

}  // namespace focal::detail
