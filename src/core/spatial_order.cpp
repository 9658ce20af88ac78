#include "core/spatial_order.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/parallel.h"

namespace focal::detail {
namespace {

/// The bits of x (at most 21) spread to every third position.
std::uint64_t spread_bits(std::uint64_t x) {
  x &= (1ULL << 21) - 1;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

/// Morton codes of the rows in the box of the finite ones, `bits` per axis; non-finite ones get
/// 2^(3 bits), above every finite code, so that they come last.
std::vector<std::uint64_t> morton_codes(PositionsRef V, int threads, int bits) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const Eigen::Vector3d p = V.row(i).transpose();
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double cells = static_cast<double>((1ULL << bits) - 1);
  std::vector<std::uint64_t> codes(static_cast<std::size_t>(V.rows()));
  parallel_for(V.rows(), threads, [&](std::int64_t i) {
    const Eigen::Vector3d p = V.row(i).transpose();
    if (!p.allFinite()) {
      codes[static_cast<std::size_t>(i)] = std::uint64_t{1} << (3 * bits);
      return;
    }
    std::uint64_t code = 0;
    for (int a = 0; a < 3; ++a) {
      const double extent = hi[a] - lo[a];
      const double t = extent > 0.0 ? (p[a] - lo[a]) / extent : 0.0;
      const auto cell = static_cast<std::uint64_t>(std::clamp(t, 0.0, 1.0) * cells);
      code |= spread_bits(cell) << a;
    }
    codes[static_cast<std::size_t>(i)] = code;
  });
  return codes;
}

}  // namespace

std::vector<int> morton_order(PositionsRef V, int threads, int bits_per_axis) {
  if (bits_per_axis < 1 || bits_per_axis > 21) {
    throw std::invalid_argument("morton_order: bits per axis must be 1 to 21");
  }
  const std::vector<std::uint64_t> codes = morton_codes(V, threads, bits_per_axis);
  // A stable counting sort on 16-bit digits (ties stay by row): the order of sorting (code, row)
  // pairs, in linear time and with 16 bytes a row of scratch where the pairs would take 32.
  // Each pass counts and places the rows of contiguous runs of
  // `order` in parallel, a run's rows of a digit after those of the runs before it: the same
  // stable order for any number of runs (and so of threads).
  constexpr int kDigitBits = 16;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
  const std::size_t n = codes.size();
  // At most 8 runs: each holds a count per digit (512 KiB), and their prefix sum is serial.
  const std::size_t runs =
      n < (std::size_t{1} << 16) ? 1 : static_cast<std::size_t>(std::min(thread_count(threads), 8));
  const auto run_begin = [&](std::size_t r) { return n * r / runs; };
  std::vector<int> order(n), next(n);
  std::iota(order.begin(), order.end(), 0);
  std::vector<std::size_t> start(runs * kBuckets);  // run r's next place for each digit
  // 3 bits_per_axis bits and the non-finite rows' bit above them.
  for (int shift = 0; shift <= 3 * bits_per_axis; shift += kDigitBits) {
    const auto digit = [&](int row) {
      return static_cast<std::size_t>(codes[static_cast<std::size_t>(row)] >> shift) &
             (kBuckets - 1);
    };
    std::fill(start.begin(), start.end(), 0);
    parallel_chunks(static_cast<std::int64_t>(runs), threads, [&](std::int64_t c) {
      const auto r = static_cast<std::size_t>(c);
      std::size_t* count = start.data() + r * kBuckets;
      for (std::size_t j = run_begin(r); j < run_begin(r + 1); ++j) ++count[digit(order[j])];
    });
    std::size_t sum = 0;
    for (std::size_t d = 0; d < kBuckets; ++d) {
      for (std::size_t r = 0; r < runs; ++r) sum += std::exchange(start[r * kBuckets + d], sum);
    }
    parallel_chunks(static_cast<std::int64_t>(runs), threads, [&](std::int64_t c) {
      const auto r = static_cast<std::size_t>(c);
      std::size_t* place = start.data() + r * kBuckets;
      for (std::size_t j = run_begin(r); j < run_begin(r + 1); ++j) {
        next[place[digit(order[j])]++] = order[j];
      }
    });
    order.swap(next);
  }
  return order;
}

RowPermutation morton_permutation(PositionsRef V, int threads) {
  RowPermutation p;
  p.order = morton_order(V, threads, kPermutationBits);
  p.position.resize(p.order.size());
  parallel_for(static_cast<std::int64_t>(p.order.size()), threads, [&](std::int64_t j) {
    p.position[static_cast<std::size_t>(p.order[static_cast<std::size_t>(j)])] =
        static_cast<int>(j);
  });
  return p;
}

}  // namespace focal::detail
