// The parallel layer (src/core/parallel.h): every element visited once, per-thread slots in
// range, exceptions carried to the caller, nested loops and concurrent callers (issue 20).
#include "core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <thread>
#include <vector>

namespace focal::detail {
namespace {

TEST(Parallel, VisitsEveryElementOnceForAnyThreadCount) {
  for (const int threads : {1, 2, 3, 8}) {
    for (const std::int64_t n : {0, 1, 1024, 1025, 100'003}) {
      std::vector<int> hits(static_cast<std::size_t>(n), 0);
      parallel_for(n, threads, [&](std::int64_t i) { ++hits[static_cast<std::size_t>(i)]; });
      for (std::int64_t i = 0; i < n; ++i) {
        ASSERT_EQ(hits[static_cast<std::size_t>(i)], 1) << "n " << n << " threads " << threads;
      }
    }
  }
}

TEST(Parallel, BlocksHaveFixedBoundaries) {
  const std::int64_t n = 10'000, block = 256;
  for (const int threads : {1, 2, 5}) {
    std::vector<std::int64_t> ends(static_cast<std::size_t>((n + block - 1) / block), -1);
    parallel_for_blocks(n, block, threads, [&](std::int64_t begin, std::int64_t end) {
      ASSERT_EQ(begin % block, 0);
      ends[static_cast<std::size_t>(begin / block)] = end;
    });
    for (std::size_t b = 0; b < ends.size(); ++b) {
      EXPECT_EQ(ends[b], std::min<std::int64_t>(n, static_cast<std::int64_t>(b + 1) * block));
    }
  }
}

TEST(Parallel, WorkerSlotsStayBelowTheThreadCount) {
  for (const int threads : {1, 2, 4}) {
    std::atomic<int> worst{0};
    parallel_chunks(1000, threads, [&](std::int64_t) {
      int seen = worst.load();
      while (worker_slot() > seen && !worst.compare_exchange_weak(seen, worker_slot())) {
      }
    });
    EXPECT_LT(worst.load(), threads);
  }
  EXPECT_EQ(worker_slot(), 0);
}

TEST(Parallel, RethrowsTheExceptionOfAChunk) {
  EXPECT_THROW(parallel_chunks(100, 2,
                               [](std::int64_t c) {
                                 if (c == 37) throw std::runtime_error("chunk 37");
                               }),
               std::runtime_error);
  // The pool still works afterwards.
  std::atomic<std::int64_t> sum{0};
  parallel_chunks(100, 2, [&](std::int64_t c) { sum += c; });
  EXPECT_EQ(sum.load(), 4950);
}

TEST(Parallel, NestedLoopsAndConcurrentCallersFinish) {
  constexpr int kCallers = 6;
  std::vector<std::int64_t> totals(kCallers, 0);
  std::vector<std::thread> callers;
  for (int k = 0; k < kCallers; ++k) {
    callers.emplace_back([&, k] {
      std::vector<std::int64_t> rows(200, 0);
      parallel_for_blocks(200 * 64, 64, 2, [&](std::int64_t begin, std::int64_t) {
        std::int64_t row = 0;
        // A loop inside a loop's body runs on the calling thread.
        parallel_chunks(64, 2, [&](std::int64_t c) { row += c; });
        rows[static_cast<std::size_t>(begin / 64)] = row;
      });
      for (const auto r : rows) totals[static_cast<std::size_t>(k)] += r;
    });
  }
  for (auto& t : callers) t.join();
  for (const auto t : totals) EXPECT_EQ(t, 200 * 2016);
}

}  // namespace
}  // namespace focal::detail
