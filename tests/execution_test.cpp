// ExecutionScope (focal/core/execution.h): the calling thread's execution settings, nested
// scopes, other threads, the loops' workers, and the same bits for any thread count it sets.
#include "focal/core/execution.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/curvature.h"
#include "test_clouds.h"
#include "test_identical.h"
#include "test_meshes.h"
#include "test_threads.h"

namespace focal {
namespace {

TEST(ExecutionScope, NestedScopesRestoreTheEnclosingOne) {
  EXPECT_EQ(current_execution().threads, 0);
  std::vector<std::string> warnings;
  {
    const ExecutionScope outer(
        {.threads = 3, .warning = [&](const std::string& w) { warnings.push_back(w); }});
    EXPECT_EQ(current_execution().threads, 3);
    EXPECT_EQ(detail::thread_count(0), 3);
    EXPECT_EQ(detail::thread_count(2), 2);  // a count asked for wins over the scope's
    {
      const ExecutionScope inner({.threads = 5});
      EXPECT_EQ(current_execution().threads, 5);
      EXPECT_EQ(detail::thread_count(0), 5);
      // Left at its default: the enclosing scope's callback.
      ASSERT_TRUE(current_execution().warning);
      current_execution().warning("from inner");
      {
        const ExecutionScope innermost({});
        EXPECT_EQ(current_execution().threads, 5);
      }
      EXPECT_EQ(current_execution().threads, 5);
    }
    EXPECT_EQ(current_execution().threads, 3);
  }
  EXPECT_EQ(current_execution().threads, 0);
  EXPECT_FALSE(current_execution().warning);
  EXPECT_EQ(warnings, std::vector<std::string>{"from inner"});
}

TEST(ExecutionScope, NegativeThreadsThrowAndLeaveTheScopeAsItWas) {
  const ExecutionScope outer({.threads = 2});
  EXPECT_THROW(ExecutionScope({.threads = -1}), InvalidInput);
  EXPECT_EQ(current_execution().threads, 2);
  // The front door opens one for its options' execution.
  EstimateOptions negative;
  negative.execution.threads = -1;
  EXPECT_THROW((void)curvature(test::flat_grid(4), negative), InvalidInput);
  EXPECT_EQ(current_execution().threads, 2);
}

TEST(ExecutionScope, AScopeOnOneThreadLeavesOtherThreadsAlone) {
  const ExecutionScope mine({.threads = 3});
  int seen_there = -1, inside_there = -1;
  std::thread other([&] {
    seen_there = current_execution().threads;
    const ExecutionScope theirs({.threads = 7});
    inside_there = current_execution().threads;
  });
  other.join();
  EXPECT_EQ(seen_there, 0);
  EXPECT_EQ(inside_there, 7);
  EXPECT_EQ(current_execution().threads, 3);
}

TEST(ExecutionScope, ALoopsBodySeesTheScopeOfTheThreadThatStartedIt) {
  std::atomic<int> other_counts{0};
  std::atomic<int> widest_slot{0};
  const auto loop = [&] {
    detail::parallel_chunks(256, 0, [&](std::int64_t) {
      if (current_execution().threads != 2) ++other_counts;
      int seen = widest_slot.load();
      while (detail::worker_slot() > seen &&
             !widest_slot.compare_exchange_weak(seen, detail::worker_slot())) {
      }
    });
  };
  test::on_threads(2, loop);
  EXPECT_EQ(other_counts.load(), 0);
  EXPECT_LT(widest_slot.load(), 2);
  // One thread: the caller alone.
  widest_slot = 0;
  test::on_threads(1, [&] {
    detail::parallel_chunks(256, 0, [&](std::int64_t) {
      if (detail::worker_slot() != 0) widest_slot = 1;
    });
  });
  EXPECT_EQ(widest_slot.load(), 0);
}

TEST(ExecutionScope, TheSameBitsOnOneTwoAndThreeThreads) {
  const Mesh mesh =
      test::analytic_surface(SurfaceKind::torus, Triangulation::irregular, 3000, 0.0, 3).mesh;
  const Mesh cloud = test::cloud_of(SurfaceKind::pear, 4000).mesh;
  for (const Mesh* input : {&mesh, &cloud}) {
    const std::string what = input->is_cloud() ? "cloud" : "mesh";
    const auto run = [&] { return curvature(*input); };
    const Estimate one = test::on_threads(1, run);
    ASSERT_GT(one.curvature.k1.size(), 0);
    for (const int threads : {2, 3}) {
      const Estimate many = test::on_threads(threads, run);
      test::expect_identical(one.curvature, many.curvature,
                             what + ", 1 vs " + std::to_string(threads) + " threads");
      EXPECT_EQ(one.N.has_value(), many.N.has_value()) << what;
      if (one.N && many.N) {
        EXPECT_TRUE(*one.N == *many.N) << what;
      }
    }
  }
}

}  // namespace
}  // namespace focal
