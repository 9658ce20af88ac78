#include "focal/points/neighbours.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/spatial_order.h"
#include "focal/core/error.h"
#include "points/argument_checks.h"
#include "points/measured_neighbours.h"
#include "points/plane_sums.h"
#include "points/point_tree.h"

namespace focal {
namespace {

using detail::Candidate;
using detail::check_threads;
using detail::PlaneSums;
using detail::PointTree;

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

void detail::check_threads(int threads) {
  if (threads < 0) throw InvalidInput("neighbours: threads must be >= 0");
}

Neighbourhoods nearest_neighbours(PositionsRef V, int k) { return nearest_neighbours(V, k, {}); }

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
      // list slots are fetched a query ahead, so that their misses overlap the query before.
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

Neighbourhoods nearest_neighbours(PositionsRef V, int k, const std::vector<char>& excluded) {
  return nearest(V, k, excluded, 0, nullptr, {});
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

Neighbourhoods radius_neighbours(PositionsRef V, double radius, int max_count) {
  return radius_neighbours(V, radius, max_count, {});
}

Neighbourhoods radius_neighbours(PositionsRef V, double radius, int max_count,
                                 const std::vector<char>& excluded) {
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    throw InvalidInput("neighbours: radius must be finite and > 0, got " + std::to_string(radius));
  }
  if (max_count < 0) throw InvalidInput("neighbours: max_count must be >= 0");
  return within_radii(V, excluded, max_count, 0, [radius](int) { return radius; });
}

Neighbourhoods adaptive_radius_neighbours(PositionsRef V, int k, double scale, int max_count,
                                          const std::vector<char>& excluded) {
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    throw InvalidInput("neighbours: the adaptive radius scale must be finite and > 0, got " +
                       std::to_string(scale));
  }
  if (max_count < 0) throw InvalidInput("neighbours: max_count must be >= 0");
  const Neighbourhoods knn = nearest_neighbours(V, k, excluded);
  const int n = knn.vertex_count();
  std::vector<double> reach(static_cast<std::size_t>(n), NAN);  // to the k-th nearest
  for (int i = 0; i < n; ++i) {
    if (knn.size(i) > 0)
      reach[static_cast<std::size_t>(i)] = (V.row(*(knn.end(i) - 1)) - V.row(i)).norm();
  }
  std::vector<double> radius(static_cast<std::size_t>(n), 0.0);
  detail::parallel_for_blocks(n, 1024, 0, [&](std::int64_t begin, std::int64_t end) {
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
  return within_radii(V, excluded, max_count, 0,
                      [&radius](int row) { return radius[static_cast<std::size_t>(row)]; });
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
