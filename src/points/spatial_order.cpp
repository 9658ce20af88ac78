#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "points/neighbours_detail.h"

namespace focal::detail {
namespace {

/// Cells per axis of the grid whose Morton order spatial_order follows: 2^10, so that a code
/// (3 x 10 bits) fits 32 bits; finer than the spacing of a million points on a surface.
constexpr int kCellBits = 10;
constexpr double kCells = 1 << kCellBits;
/// The key of a row without a finite position: above every code, so such rows come last.
constexpr std::uint32_t kNoCell = std::numeric_limits<std::uint32_t>::max();

/// The 10 bits of x spread to every third bit.
std::uint32_t spread_bits(std::uint32_t x) {
  x = (x | (x << 16)) & 0x030000FFu;
  x = (x | (x << 8)) & 0x0300F00Fu;
  x = (x | (x << 4)) & 0x030C30C3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}

/// Rows sorted by key, stable (ties by row): two counting passes over 16 bits each.
std::vector<int> sorted_by(const std::vector<std::uint32_t>& key) {
  const std::size_t n = key.size();
  std::vector<int> order(n), next(n);
  std::iota(order.begin(), order.end(), 0);
  std::vector<std::size_t> start(std::size_t{1} << 16);
  for (const int shift : {0, 16}) {
    std::fill(start.begin(), start.end(), 0);
    for (const std::uint32_t k : key) ++start[(k >> shift) & 0xFFFFu];
    std::size_t sum = 0;
    for (std::size_t& s : start) sum += std::exchange(s, sum);
    for (const int row : order) {
      next[start[(key[static_cast<std::size_t>(row)] >> shift) & 0xFFFFu]++] = row;
    }
    order.swap(next);
  }
  return order;
}

}  // namespace

std::vector<int> spatial_order(PositionsRef V, int threads) {
  Eigen::Array3d low = Eigen::Array3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Array3d high = -low;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (!V.row(i).allFinite()) continue;
    low = low.min(V.row(i).transpose().array());
    high = high.max(V.row(i).transpose().array());
  }
  const double extent = (high - low).maxCoeff();
  const double scale = extent > 0.0 ? (kCells - 1.0) / extent : 0.0;
  std::vector<std::uint32_t> key(static_cast<std::size_t>(V.rows()));
  parallel_for(V.rows(), threads, [&](std::int64_t i) {
    if (!V.row(i).allFinite()) {
      key[static_cast<std::size_t>(i)] = kNoCell;
      return;
    }
    std::uint32_t code = 0;
    for (int d = 0; d < 3; ++d) {
      const double cell = std::clamp(std::floor((V(i, d) - low[d]) * scale), 0.0, kCells - 1.0);
      code |= spread_bits(static_cast<std::uint32_t>(cell)) << d;
    }
    key[static_cast<std::size_t>(i)] = code;
  });
  return sorted_by(key);
}

}  // namespace focal::detail
