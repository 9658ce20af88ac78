// ExecutionScope (focal/core/execution.h): the calling thread's execution settings, nested
// scopes, other threads, the loops' workers, and the same bits for any thread count it sets.
#include "focal/core/execution.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "core/memory.h"
#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/curvature.h"
#include "focal/io/mesh_io.h"
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

/// Sets FOCAL_NUM_THREADS for the lifetime of the object (unset again after).
struct ThreadsVariable {
  explicit ThreadsVariable(const char* value) { setenv("FOCAL_NUM_THREADS", value, 1); }
  ~ThreadsVariable() { unsetenv("FOCAL_NUM_THREADS"); }
  ThreadsVariable(const ThreadsVariable&) = delete;
  ThreadsVariable& operator=(const ThreadsVariable&) = delete;
};

TEST(ThreadRule, CountsAboveTheMaximumAreClampedWithAWarning) {
  EXPECT_EQ(resolve_threads(7).threads, 7);
  EXPECT_TRUE(resolve_threads(7).warning.empty());
  EXPECT_EQ(resolve_threads(kMaxThreads).threads, kMaxThreads);
  EXPECT_TRUE(resolve_threads(kMaxThreads).warning.empty());
  const ThreadRequest big = resolve_threads(1000000);
  EXPECT_EQ(big.threads, kMaxThreads);
  EXPECT_NE(big.warning.find("1000000 threads asked for"), std::string::npos) << big.warning;
  EXPECT_EQ(resolve_threads(std::int64_t{1} << 40).threads, kMaxThreads);
  EXPECT_THROW((void)resolve_threads(-1), InvalidInput);
  // A scope clamps too and says so through its warning callback; the loops never count more.
  std::vector<std::string> warnings;
  const ExecutionScope scope(
      {.threads = 1000000, .warning = [&](const std::string& w) { warnings.push_back(w); }});
  EXPECT_EQ(current_execution().threads, kMaxThreads);
  EXPECT_EQ(detail::thread_count(0), kMaxThreads);
  EXPECT_EQ(detail::thread_count(1000000), kMaxThreads);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], big.warning);
}

TEST(ThreadRule, TheVariableFollowsTheSameRuleAndANonNumberIsAnError) {
  {
    const ThreadsVariable v("3");
    EXPECT_EQ(resolve_threads(0).threads, 3);
    EXPECT_EQ(detail::thread_count(0), 3);
    EXPECT_EQ(resolve_threads(2).threads, 2);  // a count asked for wins over the variable
  }
  {
    const ThreadsVariable v("1000000");
    const ThreadRequest r = resolve_threads(0);
    EXPECT_EQ(r.threads, kMaxThreads);
    EXPECT_NE(r.warning.find("FOCAL_NUM_THREADS"), std::string::npos) << r.warning;
    std::vector<std::string> warnings;
    const ExecutionScope outermost(
        {.warning = [&](const std::string& w) { warnings.push_back(w); }});
    EXPECT_EQ(current_execution().threads, kMaxThreads);
    EXPECT_EQ(warnings.size(), 1u);
  }
  {
    const ThreadsVariable v("99999999999999999999999");  // too many digits: clamped, not an error
    EXPECT_EQ(resolve_threads(0).threads, kMaxThreads);
  }
  for (const char* bad : {"abc", "-2", "1.5", "4x", " 4"}) {
    const ThreadsVariable v(bad);
    EXPECT_THROW((void)resolve_threads(0), InvalidInput) << bad;
    EXPECT_THROW(ExecutionScope({}), InvalidInput) << bad;
    EXPECT_THROW((void)detail::thread_count(0), InvalidInput) << bad;
    try {
      (void)resolve_threads(0);
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
  {
    const ThreadsVariable v("");  // empty: as unset
    EXPECT_EQ(resolve_threads(0).threads, 0);
  }
}

TEST(MemoryCheck, ARequestOverWhatIsAvailableIsAClearError) {
  const std::uint64_t available = detail::available_memory();
  ASSERT_GT(available, 0u);  // Linux: /proc/meminfo
  EXPECT_NO_THROW(detail::require_memory(1 << 20, "a small thing"));
  try {
    detail::require_memory(std::uint64_t{1} << 62, "a picture of 2^62 bytes");
    FAIL() << "no error";
  } catch (const InvalidInput& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("a picture of 2^62 bytes needs about 4.61e+09 GB of memory, more than the "),
              std::string::npos)
        << m;
    EXPECT_NE(m.find(detail::memory_text(available).substr(0, 2)), std::string::npos) << m;
  }
  EXPECT_EQ(detail::memory_text(25'000'000'000), "25 GB");
  EXPECT_EQ(detail::memory_text(1'500'000), "1.5 MB");
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

// Execution::pass_progress: each outermost pass reported on the calling thread, from 0 chunks
// done to all of them, never going back, on one thread as on several; a loop inside a loop's
// body and a loop of up to 1024 elements are not passes.
TEST(PassProgress, EachOutermostPassFromStartToEndOnTheCallingThread) {
  for (const int threads : {1, 2, 3}) {
    std::vector<PassProgress> reports;
    const std::thread::id caller = std::this_thread::get_id();
    bool elsewhere = false;
    Execution e;
    e.threads = threads;
    e.pass_progress = [&](const PassProgress& p) {
      reports.push_back(p);
      elsewhere = elsewhere || std::this_thread::get_id() != caller;
    };
    const ExecutionScope scope(e);
    std::atomic<std::int64_t> sum{0};
    detail::parallel_for(1000, 0, [&](std::int64_t i) { sum += i; });
    EXPECT_TRUE(reports.empty()) << "a loop of 1000 elements is no pass";
    detail::parallel_for(200000, 0, [&](std::int64_t i) {
      if (i % 50000 == 0) detail::parallel_for(5000, 0, [&](std::int64_t j) { sum += j; });
    });
    detail::parallel_for_blocks(300000, 4096, 0,
                                [&](std::int64_t b, std::int64_t end) { sum += end - b; });
    ASSERT_GE(reports.size(), 4U) << threads << " thread(s)";
    EXPECT_FALSE(elsewhere);
    // Two passes: parallel_for's (grain 781 of 200000: 257 chunks), then the blocks' (74).
    const std::uint64_t first = reports.front().pass;
    std::vector<std::uint64_t> passes;
    for (std::size_t r = 0; r < reports.size(); ++r) {
      const PassProgress& p = reports[r];
      if (passes.empty() || passes.back() != p.pass) {
        passes.push_back(p.pass);
        EXPECT_EQ(p.done, 0);
        if (r > 0) {
          EXPECT_EQ(reports[r - 1].done, reports[r - 1].total);
        }
      } else {
        EXPECT_GE(p.done, reports[r - 1].done);
        EXPECT_EQ(p.total, reports[r - 1].total);
      }
      EXPECT_LE(p.done, p.total);
    }
    EXPECT_EQ(passes, (std::vector<std::uint64_t>{first, first + 1}));
    EXPECT_EQ(reports.back().done, reports.back().total);
    EXPECT_EQ(reports.back().total, (300000 + 4095) / 4096);
    EXPECT_DOUBLE_EQ(reports.back().fraction(), 1.0);
  }
}

// A ReportedPass makes the loops inside it one pass: a text writer's batches (32768 lines each)
// show as one pass over all the lines, not as a pass per batch that starts at 0 again.
TEST(PassProgress, AReportedPassMakesTheLoopsInsideItOnePass) {
  std::vector<PassProgress> reports;
  Execution e;
  e.threads = 2;
  e.pass_progress = [&](const PassProgress& p) { reports.push_back(p); };
  const ExecutionScope scope(e);
  {
    detail::ReportedPass pass(3);
    for (std::int64_t k = 0; k < 3; ++k) {
      detail::parallel_for(100000, 0, [](std::int64_t) {});
      pass.advance(k + 1);
    }
    pass.finish();
  }
  Mesh cloud;
  cloud.V = Eigen::MatrixXd::Random(100000, 3);
  const auto path =
      std::filesystem::temp_directory_path() /
      ("focal_pass_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
       std::to_string(reinterpret_cast<std::uintptr_t>(&reports)) + ".xyz");
  write_xyz(path, cloud);
  std::filesystem::remove(path);
  ASSERT_GE(reports.size(), 4U);
  std::vector<std::uint64_t> passes;
  for (const PassProgress& p : reports) {
    if (passes.empty() || passes.back() != p.pass) passes.push_back(p.pass);
  }
  ASSERT_EQ(passes.size(), 2U) << "the three loops, then the writer's four batches";
  EXPECT_EQ(reports.front().total, 3);
  EXPECT_EQ(reports.back().total, 100000);
  EXPECT_EQ(reports.back().done, 100000);
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
