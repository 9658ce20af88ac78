#include "focal/points/neighbours.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <nanoflann.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/spatial_order.h"
#include "focal/core/error.h"
#include "points/measured_neighbours.h"

namespace focal {
namespace {

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
/// in cache, and read the points contiguously: on a randomly ordered 1M-point torus (k = 16),
/// the permuted copy (with the CSR written by the queries) took the kNN from 2.2 s to 1.8 s CPU,
/// and querying in leaf order rather than input order had already given 3.1x (docs/POINTS.md).
/// Leaves of 6 to 32 points gave the same time within noise; 16 kept.
class PointTree {
 public:
  /// `excluded`: empty, or #V flags of points to leave out as the non-finite ones are.
  /// `spatial`: V's rows are in a spatial order already (a copy of a cloud in Morton order), so
  /// they are taken as they come.
  PointTree(PositionsRef V, const std::vector<char>& excluded, int threads, bool spatial = false) {
    if (!excluded.empty() && excluded.size() != static_cast<std::size_t>(V.rows())) {
      throw InvalidInput("neighbours: " + std::to_string(excluded.size()) +
                         " exclusion flags for " + std::to_string(V.rows()) + " points");
    }
    points_.rows.reserve(static_cast<std::size_t>(V.rows()));
    // In a spatial order rather than by row: the build's partitions then move points that are
    // near in memory too (on the randomly ordered 1M torus its splits took 2.4 times less CPU,
    // the whole `--k 16` run 3-4% less). The lists do not depend on the tree's shape: they are
    // the nearest by distance, ties broken by row.
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
  /// thread count. The serial build was about 15% of the kNN's CPU on 1M points.
  void build(int threads) {
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
      detail::parallel_chunks(
          static_cast<std::int64_t>(level.size()), threads, [&](std::int64_t c) {
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
    detail::parallel_chunks(
        static_cast<std::int64_t>(subtrees.size()), threads, [&](std::int64_t c) {
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

  /// nanoflann's divideTree, its nodes from `nodes`.
  Node* divide(std::deque<Node>& nodes, std::size_t left, std::size_t right, Box& box) {
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

  /// The points permuted so that the tree's index array becomes the identity: the tree (split
  /// values, bounding boxes, index ranges of the leaves) is unchanged, its point j is now ours.
  void to_leaf_order(int threads) {
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

  FinitePoints points_;
  std::unique_ptr<Tree> tree_;
  std::deque<Node> top_;                 ///< the nodes of the top levels
  std::vector<std::deque<Node>> nodes_;  ///< each subtree's
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

constexpr std::int64_t kBlock = 1024;

/// CSR offsets from per-row list sizes.
Eigen::VectorXi offsets_of(const std::vector<int>& sizes) {
  Eigen::VectorXi offsets(static_cast<Eigen::Index>(sizes.size()) + 1);
  offsets[0] = 0;
  std::int64_t total = 0;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    total += sizes[i];
    if (total > std::numeric_limits<int>::max()) {
      throw InvalidInput("neighbours: the lists would not fit 32-bit offsets");
    }
    offsets[static_cast<Eigen::Index>(i) + 1] = static_cast<int>(total);
  }
  return offsets;
}

/// The lists of the tree's points, queried in parallel per block of the tree's order, then laid
/// out in row order as the CSR. Each list depends on its point alone, so neither the order nor
/// the thread count changes the result.
template <class Query>
Neighbourhoods gather(Eigen::Index n, const PointTree& tree, int threads, const Query& query) {
  const auto count = static_cast<std::int64_t>(tree.size());
  std::vector<std::vector<int>> lists(static_cast<std::size_t>((count + kBlock - 1) / kBlock));
  std::vector<int> sizes(static_cast<std::size_t>(n), 0);
  std::vector<int> start(static_cast<std::size_t>(n), 0);  // in its block's list
  detail::parallel_for_blocks(count, kBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    std::vector<int>& list = lists[static_cast<std::size_t>(begin / kBlock)];
    std::vector<Candidate> scratch;
    for (std::int64_t p = begin; p < end; ++p) {
      const auto i = static_cast<std::size_t>(tree.row(static_cast<std::uint32_t>(p)));
      start[i] = static_cast<int>(list.size());
      query(static_cast<std::size_t>(p), scratch, list);
      sizes[i] = static_cast<int>(list.size()) - start[i];
    }
  });
  Neighbourhoods out;
  out.offsets = offsets_of(sizes);
  out.indices.resize(out.offsets[n]);
  detail::parallel_for_blocks(count, kBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    const std::vector<int>& list = lists[static_cast<std::size_t>(begin / kBlock)];
    for (std::int64_t p = begin; p < end; ++p) {
      const auto i = static_cast<std::size_t>(tree.row(static_cast<std::uint32_t>(p)));
      std::copy_n(list.data() + start[i], sizes[i], out.indices.data() + out.offsets[i]);
    }
  });
  return out;
}

void check_threads(int threads) {
  if (threads < 0) throw InvalidInput("neighbours: threads must be >= 0");
}

/// The sums of a least-squares plane through points q given as offsets from the point whose
/// offset from the plane is wanted (offsets keep the plane accurate far from the origin): one
/// arithmetic for plane_offset over V's rows and for the kNN query over the tree's copies (the
/// same doubles), so both give the same bits.
struct PlaneSums {
  Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
  Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
  double reach = 0.0;
  int count = 0;

  void add(const Eigen::RowVector3d& q) { add(q, q.norm()); }
  /// add(q), with q.norm() computed by the caller (the kNN query needs it too).
  void add(const Eigen::RowVector3d& q, double norm) {
    sum += q;
    // moment += q^T q, element by element: each element is the same one product and one sum
    // (and q_r q_c = q_c q_r), without the temporary that Eigen stores in halves and reloads
    // whole (a failed store forwarding per point and neighbour: 43% of the perf samples of the
    // kNN loop outside nanoflann on the 1M torus).
    for (int r = 0; r < 3; ++r) {
      for (int c = r; c < 3; ++c) moment(r, c) += q[r] * q[c];
    }
    reach += norm;
    ++count;
  }
  /// The origin's distance to the plane and the points' RMS distance to it; NaN when fewer than
  /// 3 points or the plane is undefined.
  [[nodiscard]] detail::PlaneOffset offset() const {
    if (count < 3) return {};
    Eigen::Matrix3d full = moment;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < r; ++c) full(r, c) = full(c, r);
    }
    const Eigen::RowVector3d centroid = sum / count;
    const Eigen::Matrix3d covariance = full / count - centroid.transpose() * centroid;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(covariance);
    const Eigen::RowVector3d normal = eig.eigenvectors().col(0).transpose();
    if (!normal.allFinite()) return {};
    // A floor far below any sampling's scale: on exactly flat neighbours (spread 0) only a
    // distance above rounding counts.
    return {std::abs(centroid.dot(normal)),
            std::max(std::sqrt(std::max(eig.eigenvalues()[0], 0.0)), 1e-9 * reach / count)};
  }
};

/// The k nearest of the tree's point p (not itself), sorted by (distance, row), into `out`.
/// k + 1 for the point itself, and one more to see whether the k-th distance is tied with a
/// farther point: then every point at that distance is gathered and the tie broken by index
/// rather than by the traversal order (rare on measured data, common on grids).
class NearestQuery {
 public:
  /// `tie_rows`: null, or per row of V the index that orders its ties instead of the row
  /// (detail::nearest_neighbours).
  NearestQuery(const PointTree& tree, std::size_t k, const std::vector<int>* tie_rows = nullptr)
      : tree_(tree), k_(k), wanted_(std::min(k + 2, tree.size())), tie_rows_(tie_rows) {}
  /// Every finite point gets this many (fewer only when the cloud has fewer other points).
  [[nodiscard]] std::size_t list_size() const { return std::min(k_, tree_.size() - 1); }

  /// `measures`: null, or where the outlier tests' measures of p's list go (at p's row).
  void operator()(std::size_t p, int* out, detail::OutlierMeasures* measures = nullptr) {
    index_.resize(wanted_), distance_.resize(wanted_);
    const double* q = tree_.point(p);
    const std::size_t found = tree_.tree().knnSearch(q, wanted_, index_.data(), distance_.data());
    candidates_.clear();
    if (found == wanted_ && wanted_ >= 2 && distance_[wanted_ - 1] == distance_[wanted_ - 2]) {
      tree_.within(q, distance_[wanted_ - 1],
                   [&](double distance, std::uint32_t index) { add(distance, index); });
    } else {
      for (std::size_t j = 0; j < found; ++j) add(distance_[j], index_[j]);
    }
    // Sorted by distance already (nanoflann's insertion), so the sort only orders ties.
    std::sort(candidates_.begin(), candidates_.end());
    const int self = tree_.row(static_cast<std::uint32_t>(p));
    std::size_t kept = 0;
    for (const Found& c : candidates_) {
      if (kept == list_size()) break;
      if (c.row != self) {
        out[kept++] = c.row;
        if (measures) index_[kept - 1] = c.index;  // read after the loop, so no clash
      }
    }
    if (measures) measure(p, self, kept, *measures);
  }

 private:
  /// A candidate: ordered by (squared distance, row) as Candidate, or by (squared distance, its
  /// tie row) with tie rows; its row and tree index carried.
  struct Found {
    double distance;
    int tie;
    int row;
    std::uint32_t index;
    bool operator<(const Found& o) const {
      return distance < o.distance || (distance == o.distance && tie < o.tie);
    }
  };

  void add(double distance, std::uint32_t index) {
    const int row = tree_.row(index);
    const int tie = tie_rows_ ? (*tie_rows_)[static_cast<std::size_t>(row)] : row;
    candidates_.push_back({distance, tie, row, index});
  }

  /// outlier_points' mean distance and plane_offset over p's list (its `kept` tree indices in
  /// index_), from the tree's copies of the points, which the search has just read (in cache),
  /// rather than from V's rows (a randomly ordered cloud scatters them over all of V). The same
  /// arithmetic in the same order as outlier_points and off_surface_points: the same bits.
  void measure(std::size_t p, int self, std::size_t kept, detail::OutlierMeasures& m) const {
    const auto row = static_cast<std::size_t>(self);
    const Eigen::Map<const Eigen::RowVector3d> origin(tree_.point(p));
    // Each neighbour's distance once, for both measures (each sums them in list order).
    double sum = 0.0;
    PlaneSums plane;
    for (std::size_t j = 0; j < kept; ++j) {
      const Eigen::RowVector3d q =
          Eigen::Map<const Eigen::RowVector3d>(tree_.point(index_[j])) - Eigen::RowVector3d(origin);
      const double distance = q.norm();
      sum += distance;
      plane.add(q, distance);
    }
    if (kept > 0) m.reach[row] = sum / static_cast<int>(kept);
    const detail::PlaneOffset o = plane.offset();
    m.distance[row] = o.distance;
    m.spread[row] = o.spread;
  }

  const PointTree& tree_;
  std::size_t k_, wanted_;
  const std::vector<int>* tie_rows_;
  std::vector<std::uint32_t> index_;
  std::vector<double> distance_;
  std::vector<Found> candidates_;
};

/// Every other point within radius_of(row) of each point (none where that is not > 0), at most
/// max_count (0 = no limit), the nearest, sorted: radius_neighbours and the adaptive ones.
template <class RadiusOf>
Neighbourhoods within_radii(PositionsRef V, const std::vector<char>& excluded, int max_count,
                            int threads, const RadiusOf& radius_of) {
  const PointTree tree(V, excluded, threads);
  const std::size_t limit =
      max_count > 0 ? static_cast<std::size_t>(max_count) : std::numeric_limits<std::size_t>::max();
  return gather(V.rows(), tree, threads,
                [&](std::size_t p, std::vector<Candidate>& c, std::vector<int>& out) {
                  c.clear();
                  const int row = tree.row(static_cast<std::uint32_t>(p));
                  const double r = radius_of(row);
                  if (r > 0.0) tree.within(tree.point(p), r * r, c);
                  keep_sorted(
                      c, row,
                      limit == std::numeric_limits<std::size_t>::max() ? limit : limit + out.size(),
                      out);
                });
}

}  // namespace

Neighbourhoods nearest_neighbours(PositionsRef V, int k, int threads) {
  return nearest_neighbours(V, k, {}, threads);
}

namespace {

/// nearest_neighbours, and the outlier tests' measures of its lists into `measures` (or null),
/// ties ordered by `tie_rows` (empty: by row).
Neighbourhoods nearest(PositionsRef V, int k, const std::vector<char>& excluded, int threads,
                       detail::OutlierMeasures* measures, const std::vector<int>& tie_rows) {
  if (k < 1) throw InvalidInput("neighbours: k must be >= 1, got " + std::to_string(k));
  check_threads(threads);
  if (!tie_rows.empty() && tie_rows.size() != static_cast<std::size_t>(V.rows())) {
    throw InvalidInput("neighbours: " + std::to_string(tie_rows.size()) + " tie rows for " +
                       std::to_string(V.rows()) + " points");
  }
  const std::vector<int>* ties = tie_rows.empty() ? nullptr : &tie_rows;
  const PointTree tree(V, excluded, threads, ties != nullptr);
  const auto count = static_cast<std::int64_t>(tree.size());
  // Every finite point has the same number of neighbours: the CSR is laid out before the
  // queries, which write into it directly (no per-block lists, no second pass).
  const std::size_t size =
      count > 0 ? NearestQuery(tree, static_cast<std::size_t>(k)).list_size() : 0;
  std::vector<int> sizes(static_cast<std::size_t>(V.rows()), 0);
  detail::parallel_for(count, threads, [&](std::int64_t p) {
    sizes[static_cast<std::size_t>(tree.row(static_cast<std::uint32_t>(p)))] =
        static_cast<int>(size);
  });
  Neighbourhoods out;
  out.offsets = offsets_of(sizes);
  out.indices.resize(out.offsets[V.rows()]);
  if (measures) {
    for (std::vector<double>* m : {&measures->reach, &measures->distance, &measures->spread}) {
      m->assign(static_cast<std::size_t>(V.rows()), NAN);
    }
  }
  detail::parallel_for_blocks(count, kBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    NearestQuery query(tree, static_cast<std::size_t>(k), ties);
    for (std::int64_t p = begin; p < end; ++p) {
      // The rows of the next points, in leaf order, are scattered over V's: their offsets and
      // list slots are fetched a query ahead (a query takes about 1 us, a miss 0.1 us).
      if (p + 2 < end)
        __builtin_prefetch(&out.offsets[tree.row(static_cast<std::uint32_t>(p + 2))]);
      if (p + 1 < end) {
        const auto next = static_cast<std::size_t>(tree.row(static_cast<std::uint32_t>(p + 1)));
        __builtin_prefetch(out.indices.data() + out.offsets[static_cast<Eigen::Index>(next)], 1);
        if (measures) {
          __builtin_prefetch(measures->reach.data() + next, 1);
          __builtin_prefetch(measures->distance.data() + next, 1);
          __builtin_prefetch(measures->spread.data() + next, 1);
        }
      }
      const int i = tree.row(static_cast<std::uint32_t>(p));
      query(static_cast<std::size_t>(p), out.indices.data() + out.offsets[i], measures);
    }
  });
  return out;
}

}  // namespace

Neighbourhoods nearest_neighbours(PositionsRef V, int k, const std::vector<char>& excluded,
                                  int threads) {
  return nearest(V, k, excluded, threads, nullptr, {});
}

namespace detail {

Neighbourhoods nearest_neighbours(PositionsRef V, int k, const std::vector<char>& excluded,
                                  int threads, const std::vector<int>& tie_rows) {
  return nearest(V, k, excluded, threads, nullptr, tie_rows);
}

MeasuredNeighbours measured_nearest_neighbours(PositionsRef V, int k,
                                               const std::vector<char>& excluded, int threads,
                                               const std::vector<int>& tie_rows) {
  MeasuredNeighbours out;
  out.neighbours = nearest(V, k, excluded, threads, &out.measures, tie_rows);
  return out;
}

}  // namespace detail

Neighbourhoods radius_neighbours(PositionsRef V, double radius, int max_count, int threads) {
  return radius_neighbours(V, radius, max_count, {}, threads);
}

Neighbourhoods radius_neighbours(PositionsRef V, double radius, int max_count,
                                 const std::vector<char>& excluded, int threads) {
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    throw InvalidInput("neighbours: radius must be finite and > 0, got " + std::to_string(radius));
  }
  if (max_count < 0) throw InvalidInput("neighbours: max_count must be >= 0");
  check_threads(threads);
  return within_radii(V, excluded, max_count, threads, [radius](int) { return radius; });
}

Neighbourhoods adaptive_radius_neighbours(PositionsRef V, int k, double scale, int max_count,
                                          const std::vector<char>& excluded, int threads) {
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    throw InvalidInput("neighbours: the adaptive radius scale must be finite and > 0, got " +
                       std::to_string(scale));
  }
  if (max_count < 0) throw InvalidInput("neighbours: max_count must be >= 0");
  const Neighbourhoods knn = nearest_neighbours(V, k, excluded, threads);
  const int n = knn.vertex_count();
  std::vector<double> reach(static_cast<std::size_t>(n), NAN);  // to the k-th nearest
  for (int i = 0; i < n; ++i) {
    if (knn.size(i) > 0)
      reach[static_cast<std::size_t>(i)] = (V.row(*(knn.end(i) - 1)) - V.row(i)).norm();
  }
  std::vector<double> radius(static_cast<std::size_t>(n), 0.0);
  detail::parallel_for_blocks(n, 1024, threads, [&](std::int64_t begin, std::int64_t end) {
    std::vector<double> around;
    for (std::int64_t i = begin; i < end; ++i) {
      const int p = static_cast<int>(i);
      if (knn.size(p) == 0) continue;
      around.assign(1, reach[static_cast<std::size_t>(p)]);
      for (const int* j = knn.begin(p); j != knn.end(p); ++j)
        around.push_back(reach[static_cast<std::size_t>(*j)]);
      const auto middle = around.begin() + static_cast<std::ptrdiff_t>(around.size() / 2);
      std::nth_element(around.begin(), middle, around.end());
      radius[static_cast<std::size_t>(i)] = scale * *middle;
    }
  });
  return within_radii(V, excluded, max_count, threads,
                      [&radius](int row) { return radius[static_cast<std::size_t>(row)]; });
}

namespace {

void check_ratio(const char* test, double ratio) {
  if (!(ratio > 1.0) || !std::isfinite(ratio)) {
    throw InvalidInput(std::string(test) + ": ratio must be finite and > 1, got " +
                       std::to_string(ratio));
  }
}

void check_lists(const char* test, PositionsRef V, const Neighbourhoods& neighbours) {
  if (neighbours.vertex_count() != V.rows()) {
    throw InvalidInput(std::string(test) + ": the neighbourhoods are not V's");
  }
}

}  // namespace

std::vector<char> outlier_points(PositionsRef V, const Neighbourhoods& neighbours, double ratio,
                                 int threads) {
  check_ratio("outlier_points", ratio);
  check_threads(threads);
  check_lists("outlier_points", V, neighbours);
  const int n = neighbours.vertex_count();
  std::vector<double> reach(static_cast<std::size_t>(n), NAN);
  detail::parallel_for(n, threads, [&](std::int64_t i) {
    const int p = static_cast<int>(i);
    if (neighbours.size(p) == 0) return;
    double sum = 0.0;
    for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
      sum += (V.row(*j) - V.row(p)).norm();
    }
    reach[static_cast<std::size_t>(i)] = sum / neighbours.size(p);
  });
  return detail::outlier_points(V, neighbours, reach, ratio, threads);
}

std::vector<char> detail::outlier_points(PositionsRef V, const Neighbourhoods& neighbours,
                                         const std::vector<double>& reach, double ratio,
                                         int threads) {
  check_ratio("outlier_points", ratio);
  check_threads(threads);
  check_lists("outlier_points", V, neighbours);
  const int n = neighbours.vertex_count();
  if (reach.size() != static_cast<std::size_t>(n)) {
    throw InvalidInput("outlier_points: the measures are not the neighbourhoods'");
  }
  std::vector<char> outlier(static_cast<std::size_t>(n), 0);
  // r > ratio x (the median m of the neighbours' finite reaches, element size / 2 of them
  // sorted) without the median: x -> ratio * x is monotone in floating point too, so the test
  // holds exactly when more than size / 2 of them have ratio * reach < r (then the sorted
  // elements 0 .. size / 2 do, m among them; and conversely). The same flags as an nth_element
  // per point.
  detail::parallel_for(n, threads, [&](std::int64_t i) {
    const int p = static_cast<int>(i);
    const double r = reach[static_cast<std::size_t>(i)];
    int finite = 0, below = 0;
    for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
      const double a = reach[static_cast<std::size_t>(*j)];
      if (!std::isfinite(a)) continue;
      ++finite;
      below += r > ratio * a;
    }
    outlier[static_cast<std::size_t>(i)] = finite > 0 && below > finite / 2;
  });
  return outlier;
}

namespace {

/// A point's PlaneOffset over its neighbours, leaving out `without` (-1: none).
detail::PlaneOffset plane_offset(PositionsRef V, const Neighbourhoods& neighbours, int p,
                                 int without) {
  const Eigen::RowVector3d origin = V.row(p);
  PlaneSums plane;
  for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
    if (*j == without) continue;
    const Eigen::RowVector3d q = V.row(*j) - origin;
    plane.add(q);
  }
  if (!origin.allFinite()) return {};
  return plane.offset();
}

/// The median over the neighbours of p of their plane_offset distance without p: how far a
/// point on this sampling sits off its neighbours' plane, p not counted (NaN when none has one).
double neighbours_offset_without(PositionsRef V, const Neighbourhoods& neighbours, int p,
                                 std::vector<double>& around) {
  around.clear();
  for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
    const double d = plane_offset(V, neighbours, *j, p).distance;
    if (std::isfinite(d)) around.push_back(d);
  }
  if (around.empty()) return NAN;
  const auto middle = around.begin() + static_cast<std::ptrdiff_t>(around.size() / 2);
  std::nth_element(around.begin(), middle, around.end());
  return *middle;
}

/// off_surface_points with each point's own PlaneOffset from offset_of(p).
template <class OffsetOf>
std::vector<char> off_surface(PositionsRef V, const Neighbourhoods& neighbours, double ratio,
                              int threads, const OffsetOf& offset_of) {
  std::vector<char> off(static_cast<std::size_t>(neighbours.vertex_count()), 0);
  detail::parallel_for_blocks(
      neighbours.vertex_count(), 1024, threads, [&](std::int64_t begin, std::int64_t end) {
        std::vector<double> around;
        for (std::int64_t i = begin; i < end; ++i) {
          const int p = static_cast<int>(i);
          const detail::PlaneOffset o = offset_of(p);
          if (!(o.distance > ratio * o.spread)) continue;
          // A candidate (rare): kept when its neighbours, each without it, sit nearly as far off
          // their own neighbours' planes: a regular sampling, such as the pole of a sphere
          // sampled in rings, whose 16 nearest are one ring (spread ~0) with the pole its
          // sagitta above. Half the ratio: the poles of CGAL's sphere926.pwn sit 2-3 times their
          // neighbours' offset; the near-surface outliers of the analytic clouds far more (none
          // kept by it).
          const double typical = neighbours_offset_without(V, neighbours, p, around);
          off[static_cast<std::size_t>(i)] = !(o.distance <= 0.5 * ratio * typical);
        }
      });
  return off;
}

}  // namespace

std::vector<char> off_surface_points(PositionsRef V, const Neighbourhoods& neighbours, double ratio,
                                     int threads) {
  check_ratio("off_surface_points", ratio);
  check_threads(threads);
  check_lists("off_surface_points", V, neighbours);
  return off_surface(V, neighbours, ratio, threads,
                     [&](int p) { return plane_offset(V, neighbours, p, -1); });
}

std::vector<char> detail::off_surface_points(PositionsRef V, const Neighbourhoods& neighbours,
                                             const OutlierMeasures& measures, double ratio,
                                             int threads) {
  check_ratio("off_surface_points", ratio);
  check_threads(threads);
  check_lists("off_surface_points", V, neighbours);
  const auto n = static_cast<std::size_t>(neighbours.vertex_count());
  if (measures.distance.size() != n || measures.spread.size() != n) {
    throw InvalidInput("off_surface_points: the measures are not the neighbourhoods'");
  }
  return off_surface(V, neighbours, ratio, threads, [&](int p) {
    const auto i = static_cast<std::size_t>(p);
    return PlaneOffset{measures.distance[i], measures.spread[i]};
  });
}

double mean_spacing(PositionsRef V, const Neighbourhoods& neighbours) {
  return detail::mean_spacing(V, neighbours, 0);
}

double detail::mean_spacing(PositionsRef V, const Neighbourhoods& neighbours, int threads,
                            const std::vector<int>& tie_rows) {
  check_threads(threads);
  const int n = neighbours.vertex_count();
  if (!tie_rows.empty() && tie_rows.size() != static_cast<std::size_t>(n)) {
    throw InvalidInput("mean_spacing: " + std::to_string(tie_rows.size()) + " tie rows for " +
                       std::to_string(n) + " points");
  }
  // The distances in parallel (each a read of a row scattered over V), each stored at its
  // point's row before any permutation (NaN: no list); their sum in that order: the same bits
  // for any thread count and any permutation.
  std::vector<double> nearest(static_cast<std::size_t>(n), NAN);
  detail::parallel_for(n, threads, [&](std::int64_t i) {
    const int p = static_cast<int>(i);
    if (neighbours.size(p) == 0) return;
    const auto at = static_cast<std::size_t>(tie_rows.empty() ? p : tie_rows[p]);
    nearest[at] = (V.row(*neighbours.begin(p)) - V.row(p)).norm();
  });
  double sum = 0.0;
  std::int64_t count = 0;
  for (const double d : nearest) {
    if (std::isnan(d)) continue;
    sum += d;
    ++count;
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

Neighbourhoods detail::unpermuted_neighbours(const Neighbourhoods& copy, const RowPermutation& p,
                                             int threads) {
  const auto n = static_cast<std::int64_t>(p.order.size());
  if (copy.vertex_count() != n || p.position.size() != p.order.size()) {
    throw InvalidInput("neighbours: the lists are not the permuted cloud's");
  }
  std::vector<int> sizes(static_cast<std::size_t>(n));
  detail::parallel_for(n, threads, [&](std::int64_t i) {
    sizes[static_cast<std::size_t>(i)] = copy.size(p.position[static_cast<std::size_t>(i)]);
  });
  Neighbourhoods out;
  out.offsets = offsets_of(sizes);
  out.indices.resize(out.offsets[n]);
  detail::parallel_for(n, threads, [&](std::int64_t i) {
    // Each list's row in the copy, and the renaming of its entries, are scattered reads: a
    // chain of three misses (offset, list, name) per row, started ahead of time.
    if (i + 16 < n) __builtin_prefetch(&copy.offsets[p.position[static_cast<std::size_t>(i + 16)]]);
    if (i + 8 < n) {
      const int ahead = p.position[static_cast<std::size_t>(i + 8)];
      __builtin_prefetch(copy.begin(ahead));
      __builtin_prefetch(&p.order[static_cast<std::size_t>(ahead)]);
    }
    const int from = p.position[static_cast<std::size_t>(i)];
    int* to = out.indices.data() + out.offsets[i];
    for (const int* j = copy.begin(from); j != copy.end(from); ++j)
      *to++ = p.order[static_cast<std::size_t>(*j)];
  });
  return out;
}

}  // namespace focal
