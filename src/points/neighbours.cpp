#include "focal/points/neighbours.h"

#include <Eigen/Eigenvalues>
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
  PointTree(PositionsRef V, const std::vector<char>& excluded) {
    if (!excluded.empty() && excluded.size() != static_cast<std::size_t>(V.rows())) {
      throw InvalidInput("neighbours: " + std::to_string(excluded.size()) +
                         " exclusion flags for " + std::to_string(V.rows()) + " points");
    }
    points_.rows.reserve(static_cast<std::size_t>(V.rows()));
    for (Eigen::Index i = 0; i < V.rows(); ++i) {
      const bool out = !excluded.empty() && excluded[static_cast<std::size_t>(i)] != 0;
      if (!out && V.row(i).allFinite()) points_.rows.push_back(static_cast<int>(i));
    }
    points_.xyz.resize(3 * points_.rows.size());
    for (std::size_t j = 0; j < points_.rows.size(); ++j) {
      for (int d = 0; d < 3; ++d) points_.xyz[3 * j + d] = V(points_.rows[j], d);
    }
    tree_ = std::make_unique<Tree>(3, points_, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    to_leaf_order();
  }
  [[nodiscard]] const Tree& tree() const { return *tree_; }
  [[nodiscard]] int row(std::uint32_t index) const { return points_.rows[index]; }
  [[nodiscard]] std::size_t size() const { return points_.rows.size(); }
  [[nodiscard]] const double* point(std::size_t index) const { return points_.point(index); }

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
  /// The points permuted so that the tree's index array becomes the identity: the tree (split
  /// values, bounding boxes, index ranges of the leaves) is unchanged, its point j is now ours.
  void to_leaf_order() {
    std::vector<std::uint32_t>& order = tree_->vAcc;
    std::vector<double> xyz(points_.xyz.size());
    std::vector<int> rows(points_.rows.size());
    for (std::size_t j = 0; j < order.size(); ++j) {
      std::copy_n(points_.point(order[j]), 3, xyz.data() + 3 * j);
      rows[j] = points_.rows[order[j]];
      order[j] = static_cast<std::uint32_t>(j);
    }
    points_.xyz.swap(xyz);
    points_.rows.swap(rows);
  }

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

/// The k nearest of the tree's point p (not itself), sorted by (distance, row), into `out`.
/// k + 1 for the point itself, and one more to see whether the k-th distance is tied with a
/// farther point: then every point at that distance is gathered and the tie broken by index
/// rather than by the traversal order (rare on measured data, common on grids).
class NearestQuery {
 public:
  NearestQuery(const PointTree& tree, std::size_t k)
      : tree_(tree), k_(k), wanted_(std::min(k + 2, tree.size())) {}
  /// Every finite point gets this many (fewer only when the cloud has fewer other points).
  [[nodiscard]] std::size_t list_size() const { return std::min(k_, tree_.size() - 1); }

  void operator()(std::size_t p, int* out) {
    index_.resize(wanted_), distance_.resize(wanted_);
    const double* q = tree_.point(p);
    const std::size_t found = tree_.tree().knnSearch(q, wanted_, index_.data(), distance_.data());
    candidates_.clear();
    if (found == wanted_ && wanted_ >= 2 && distance_[wanted_ - 1] == distance_[wanted_ - 2]) {
      tree_.within(q, distance_[wanted_ - 1], candidates_);
    } else {
      for (std::size_t j = 0; j < found; ++j)
        candidates_.emplace_back(distance_[j], tree_.row(index_[j]));
    }
    // Sorted by distance already (nanoflann's insertion), so the sort only orders ties.
    std::sort(candidates_.begin(), candidates_.end());
    const int self = tree_.row(static_cast<std::uint32_t>(p));
    std::size_t kept = 0;
    for (const Candidate& c : candidates_) {
      if (kept == list_size()) break;
      if (c.second != self) out[kept++] = c.second;
    }
  }

 private:
  const PointTree& tree_;
  std::size_t k_, wanted_;
  std::vector<std::uint32_t> index_;
  std::vector<double> distance_;
  std::vector<Candidate> candidates_;
};

/// Every other point within radius_of(row) of each point (none where that is not > 0), at most
/// max_count (0 = no limit), the nearest, sorted: radius_neighbours and the adaptive ones.
template <class RadiusOf>
Neighbourhoods within_radii(PositionsRef V, const std::vector<char>& excluded, int max_count,
                            int threads, const RadiusOf& radius_of) {
  const PointTree tree(V, excluded);
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

Neighbourhoods nearest_neighbours(PositionsRef V, int k, const std::vector<char>& excluded,
                                  int threads) {
  if (k < 1) throw InvalidInput("neighbours: k must be >= 1, got " + std::to_string(k));
  check_threads(threads);
  const PointTree tree(V, excluded);
  const auto count = static_cast<std::int64_t>(tree.size());
  // Every finite point has the same number of neighbours: the CSR is laid out before the
  // queries, which write into it directly (no per-block lists, no second pass).
  const std::size_t size =
      count > 0 ? NearestQuery(tree, static_cast<std::size_t>(k)).list_size() : 0;
  std::vector<int> sizes(static_cast<std::size_t>(V.rows()), 0);
  for (std::int64_t p = 0; p < count; ++p) {
    sizes[static_cast<std::size_t>(tree.row(static_cast<std::uint32_t>(p)))] =
        static_cast<int>(size);
  }
  Neighbourhoods out;
  out.offsets = offsets_of(sizes);
  out.indices.resize(out.offsets[V.rows()]);
  detail::parallel_for_blocks(count, kBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    NearestQuery query(tree, static_cast<std::size_t>(k));
    for (std::int64_t p = begin; p < end; ++p) {
      const int i = tree.row(static_cast<std::uint32_t>(p));
      query(static_cast<std::size_t>(p), out.indices.data() + out.offsets[i]);
    }
  });
  return out;
}

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

std::vector<char> outlier_points(PositionsRef V, const Neighbourhoods& neighbours, double ratio,
                                 int threads) {
  if (!(ratio > 1.0) || !std::isfinite(ratio)) {
    throw InvalidInput("outlier_points: ratio must be finite and > 1, got " +
                       std::to_string(ratio));
  }
  check_threads(threads);
  const int n = neighbours.vertex_count();
  if (n != V.rows()) throw InvalidInput("outlier_points: the neighbourhoods are not V's");
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
  std::vector<char> outlier(static_cast<std::size_t>(n), 0);
  detail::parallel_for_blocks(n, 1024, threads, [&](std::int64_t begin, std::int64_t end) {
    std::vector<double> around;
    for (std::int64_t i = begin; i < end; ++i) {
      const int p = static_cast<int>(i);
      around.clear();
      for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
        if (std::isfinite(reach[static_cast<std::size_t>(*j)])) {
          around.push_back(reach[static_cast<std::size_t>(*j)]);
        }
      }
      if (around.empty()) continue;
      const auto middle = around.begin() + static_cast<std::ptrdiff_t>(around.size() / 2);
      std::nth_element(around.begin(), middle, around.end());
      const double r = reach[static_cast<std::size_t>(i)];
      outlier[static_cast<std::size_t>(i)] = r > ratio * *middle;
    }
  });
  return outlier;
}

namespace {

/// A point's distance to the least-squares plane of its neighbours, leaving out `without` (-1:
/// none), and the RMS distance of those neighbours to that plane; NaN when fewer than 3
/// neighbours remain or the plane is undefined.
struct PlaneOffset {
  double distance = NAN;
  double spread = NAN;
};

PlaneOffset plane_offset(PositionsRef V, const Neighbourhoods& neighbours, int p, int without) {
  // Offsets from the point keep the plane accurate far from the origin.
  const Eigen::RowVector3d origin = V.row(p);
  Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
  Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
  double reach = 0.0;
  int count = 0;
  for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
    if (*j == without) continue;
    const Eigen::RowVector3d q = V.row(*j) - origin;
    sum += q;
    moment += q.transpose() * q;
    reach += q.norm();
    ++count;
  }
  if (count < 3 || !origin.allFinite()) return {};
  const Eigen::RowVector3d centroid = sum / count;
  const Eigen::Matrix3d covariance = moment / count - centroid.transpose() * centroid;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(covariance);
  const Eigen::RowVector3d normal = eig.eigenvectors().col(0).transpose();
  if (!normal.allFinite()) return {};
  // A floor far below any sampling's scale: on exactly flat neighbours (spread 0) only a
  // distance above rounding counts.
  return {std::abs(centroid.dot(normal)),
          std::max(std::sqrt(std::max(eig.eigenvalues()[0], 0.0)), 1e-9 * reach / count)};
}

/// The median over the neighbours of p of their plane_offset distance without p: how far a
/// point on this sampling sits off its neighbours' plane, p not counted (NaN when none has one).
double neighbours_offset_without(PositionsRef V, const Neighbourhoods& neighbours, int p) {
  std::vector<double> around;
  for (const int* j = neighbours.begin(p); j != neighbours.end(p); ++j) {
    const double d = plane_offset(V, neighbours, *j, p).distance;
    if (std::isfinite(d)) around.push_back(d);
  }
  if (around.empty()) return NAN;
  const auto middle = around.begin() + static_cast<std::ptrdiff_t>(around.size() / 2);
  std::nth_element(around.begin(), middle, around.end());
  return *middle;
}

}  // namespace

std::vector<char> off_surface_points(PositionsRef V, const Neighbourhoods& neighbours, double ratio,
                                     int threads) {
  if (!(ratio > 1.0) || !std::isfinite(ratio)) {
    throw InvalidInput("off_surface_points: ratio must be finite and > 1, got " +
                       std::to_string(ratio));
  }
  check_threads(threads);
  const int n = neighbours.vertex_count();
  if (n != V.rows()) throw InvalidInput("off_surface_points: the neighbourhoods are not V's");
  std::vector<char> off(static_cast<std::size_t>(n), 0);
  detail::parallel_for_blocks(n, 1024, threads, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const int p = static_cast<int>(i);
      const PlaneOffset o = plane_offset(V, neighbours, p, -1);
      if (!(o.distance > ratio * o.spread)) continue;
      // A candidate (rare): kept when its neighbours, each without it, sit nearly as far off
      // their own neighbours' planes: a regular sampling, such as the pole of a sphere sampled
      // in rings, whose 16 nearest are one ring (spread ~0) with the pole its sagitta above.
      // Half the ratio: the poles of CGAL's sphere926.pwn sit 2-3 times their neighbours'
      // offset; the near-surface outliers of the analytic clouds far more (none kept by it).
      const double typical = neighbours_offset_without(V, neighbours, p);
      off[static_cast<std::size_t>(i)] = !(o.distance <= 0.5 * ratio * typical);
    }
  });
  return off;
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
