#include "focal/points/neighbours.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <nanoflann.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"

namespace focal {
namespace {

/// (squared distance, row): ordered by distance, then index, so that ties do not depend on the
/// tree's traversal.
using Candidate = std::pair<double, int>;

/// The finite rows of V, as nanoflann's dataset adaptor reads them.
struct FinitePoints {
  PositionsRef V;
  std::vector<int> rows;  ///< tree index -> row of V

  [[nodiscard]] std::size_t kdtree_get_point_count() const { return rows.size(); }
  [[nodiscard]] double kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return V(rows[i], static_cast<Eigen::Index>(dim));
  }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, FinitePoints>,
                                                 FinitePoints, 3, std::uint32_t>;

/// A tree over the finite points of V. Leaves of 8, 16 and 32 points gave the same kNN time
/// within noise (1M points, k = 16); 16 kept.
class PointTree {
 public:
  explicit PointTree(PositionsRef V) : points_{V, {}} {
    points_.rows.reserve(static_cast<std::size_t>(V.rows()));
    for (Eigen::Index i = 0; i < V.rows(); ++i) {
      if (V.row(i).allFinite()) points_.rows.push_back(static_cast<int>(i));
    }
    tree_ = std::make_unique<Tree>(3, points_, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  }
  [[nodiscard]] const Tree& tree() const { return *tree_; }
  [[nodiscard]] int row(std::uint32_t index) const { return points_.rows[index]; }
  [[nodiscard]] std::size_t size() const { return points_.rows.size(); }

  /// The finite rows in the tree's leaf order: neighbouring queries in this order walk the same
  /// leaves, which stay in cache (on a randomly ordered 1M-point cloud, 2.3x faster than input
  /// order; docs/POINTS.md).
  [[nodiscard]] std::vector<int> leaf_order() const {
    std::vector<int> order(tree_->vAcc.size());
    for (std::size_t p = 0; p < order.size(); ++p) order[p] = row(tree_->vAcc[p]);
    return order;
  }

  /// Every point at squared distance <= d2 from q (nanoflann's radius test is strict: d2 is
  /// raised to the next double), appended to `out`.
  void within(const double* q, double d2, std::vector<Candidate>& out) const {
    std::vector<std::pair<std::uint32_t, double>> matches;
    nanoflann::SearchParams params;
    params.sorted = false;
    tree_->radiusSearch(q, std::nextafter(d2, INFINITY), matches, params);
    for (const auto& [index, distance] : matches) {
      if (distance <= d2) out.emplace_back(distance, row(index));
    }
  }

 private:
  FinitePoints points_;
  std::unique_ptr<Tree> tree_;
};

/// One point's list (candidates sorted, the point itself removed, at most `limit`) appended.
void keep_sorted(std::vector<Candidate>& candidates, int self, std::size_t limit,
                 std::vector<int>& out) {
  std::sort(candidates.begin(), candidates.end());
  for (const Candidate& c : candidates) {
    if (out.size() == limit) break;
    if (c.second != self) out.push_back(c.second);
  }
}

/// The lists of the points in `order` (the finite rows, in the tree's leaf order), gathered in
/// parallel per block of that order, then laid out in row order as the CSR. Each list depends on
/// its point alone, so neither the order nor the thread count changes the result.
template <class Query>
Neighbourhoods gather(Eigen::Index n, const std::vector<int>& order, int threads,
                      const Query& query) {
  constexpr std::int64_t kBlock = 1024;
  const auto count = static_cast<std::int64_t>(order.size());
  std::vector<std::vector<int>> lists(static_cast<std::size_t>((count + kBlock - 1) / kBlock));
  std::vector<int> sizes(static_cast<std::size_t>(n), 0);
  std::vector<int> start(static_cast<std::size_t>(n), 0);  // in its block's list
  detail::parallel_for_blocks(count, kBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    std::vector<int>& list = lists[static_cast<std::size_t>(begin / kBlock)];
    std::vector<Candidate> scratch;
    for (std::int64_t p = begin; p < end; ++p) {
      const auto i = static_cast<std::size_t>(order[static_cast<std::size_t>(p)]);
      start[i] = static_cast<int>(list.size());
      query(static_cast<int>(i), scratch, list);
      sizes[i] = static_cast<int>(list.size()) - start[i];
    }
  });
  Neighbourhoods out;
  out.offsets.resize(n + 1);
  out.offsets[0] = 0;
  std::int64_t total = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    total += sizes[static_cast<std::size_t>(i)];
    if (total > std::numeric_limits<int>::max()) {
      throw InvalidInput("neighbours: the lists would not fit 32-bit offsets");
    }
    out.offsets[i + 1] = static_cast<int>(total);
  }
  out.indices.resize(total);
  detail::parallel_for_blocks(count, kBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    const std::vector<int>& list = lists[static_cast<std::size_t>(begin / kBlock)];
    for (std::int64_t p = begin; p < end; ++p) {
      const auto i = static_cast<std::size_t>(order[static_cast<std::size_t>(p)]);
      std::copy_n(list.data() + start[i], sizes[i], out.indices.data() + out.offsets[i]);
    }
  });
  return out;
}

void check_threads(int threads) {
  if (threads < 0) throw InvalidInput("neighbours: threads must be >= 0");
}

}  // namespace

Neighbourhoods nearest_neighbours(PositionsRef V, int k, int threads) {
  if (k < 1) throw InvalidInput("neighbours: k must be >= 1, got " + std::to_string(k));
  check_threads(threads);
  const PointTree tree(V);
  // k + 1 for the point itself, and one more to see whether the k-th distance is tied with a
  // farther point: then every point at that distance is gathered and the tie broken by index
  // rather than by the traversal order (rare on measured data, common on grids).
  const std::size_t wanted = std::min<std::size_t>(static_cast<std::size_t>(k) + 2, tree.size());
  return gather(V.rows(), tree.leaf_order(), threads,
                [&](int i, std::vector<Candidate>& c, std::vector<int>& out) {
                  if (wanted == 0) return;
                  std::uint32_t index[64];
                  double distance[64];
                  std::vector<std::uint32_t> big_index;
                  std::vector<double> big_distance;
                  std::uint32_t* idx = index;
                  double* dist = distance;
                  if (wanted > 64) {
                    big_index.resize(wanted), big_distance.resize(wanted);
                    idx = big_index.data(), dist = big_distance.data();
                  }
                  const double q[3] = {V(i, 0), V(i, 1), V(i, 2)};
                  const std::size_t found = tree.tree().knnSearch(q, wanted, idx, dist);
                  c.clear();
                  if (found == wanted && wanted >= 2 && dist[wanted - 1] == dist[wanted - 2]) {
                    tree.within(q, dist[wanted - 1], c);
                  } else {
                    for (std::size_t j = 0; j < found; ++j)
                      c.emplace_back(dist[j], tree.row(idx[j]));
                  }
                  keep_sorted(c, i, static_cast<std::size_t>(k) + out.size(), out);
                });
}

Neighbourhoods radius_neighbours(PositionsRef V, double radius, int max_count, int threads) {
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    throw InvalidInput("neighbours: radius must be finite and > 0, got " + std::to_string(radius));
  }
  if (max_count < 0) throw InvalidInput("neighbours: max_count must be >= 0");
  check_threads(threads);
  const PointTree tree(V);
  const std::size_t limit =
      max_count > 0 ? static_cast<std::size_t>(max_count) : std::numeric_limits<std::size_t>::max();
  return gather(V.rows(), tree.leaf_order(), threads,
                [&](int i, std::vector<Candidate>& c, std::vector<int>& out) {
                  const double q[3] = {V(i, 0), V(i, 1), V(i, 2)};
                  c.clear();
                  tree.within(q, radius * radius, c);
                  keep_sorted(
                      c, i,
                      limit == std::numeric_limits<std::size_t>::max() ? limit : limit + out.size(),
                      out);
                });
}

double mean_spacing(PositionsRef V, const Neighbourhoods& neighbours) {
  double sum = 0.0;
  std::int64_t count = 0;
  for (int i = 0; i < neighbours.vertex_count(); ++i) {
    if (neighbours.size(i) == 0) continue;
    sum += (V.row(*neighbours.begin(i)) - V.row(i)).norm();
    ++count;
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

}  // namespace focal
