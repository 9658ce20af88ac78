#pragma once
/// \file execution.h
/// How a call runs, apart from what it computes: thread count, progress, messages, cancellation,
/// in one struct that the front door (focal/curvature.h) takes as EstimateOptions::execution,
/// and that an ExecutionScope sets for every focal call made on the calling thread (the
/// functions below the front door take no thread count of their own).
/// Nothing here changes a result: every field gives the same bits for any setting.

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace focal {

/// A stage of a long call: reported when it begins (fraction 0) and when it ends (fraction 1).
struct Progress {
  std::string_view stage;  ///< "normals", "curvature", "cloud curvature", ...
  double fraction = 0.0;   ///< 0 at the start of the stage, 1 at its end
};

/// How far one parallel pass of a stage has come. A stage runs one or more passes over its
/// vertices, faces or points (how many depends on the input and the options), so this is the
/// fraction of the pass running now, not of the stage: a display shows it as such.
struct PassProgress {
  std::int64_t done = 0;   ///< chunks of the pass done (each a fixed share of its elements)
  std::int64_t total = 0;  ///< chunks of the pass, > 1
  std::uint64_t pass = 0;  ///< counts the passes started in this process (from 1): a new value
                           ///< is a new pass
  [[nodiscard]] double fraction() const {
    return total > 0 ? static_cast<double>(done) / static_cast<double>(total) : 0.0;
  }
};

/// The most threads focal runs one loop on. A larger count (Execution::threads, --threads,
/// FOCAL_NUM_THREADS, Python's threads=) is clamped to it with a warning: the worker pool has
/// one thread per CPU anyway (docs/PERFORMANCE.md, "Threads"), and every thread counted costs
/// per-thread scratch memory whether or not a CPU runs it.
inline constexpr int kMaxThreads = 1024;

/// A requested thread count resolved by the one rule of kMaxThreads.
struct ThreadRequest {
  int threads = 0;      ///< what is used: 0 (every CPU) or a count in [1, kMaxThreads]
  std::string warning;  ///< not empty when the request was clamped: what was asked and used
};

/// The one rule for a thread count: `requested` > 0 clamped to kMaxThreads; 0 the value of
/// FOCAL_NUM_THREADS when it is set to a count > 0 (clamped the same way), else 0.
/// \throw InvalidInput when `requested` < 0, or FOCAL_NUM_THREADS is set (not empty) but is not
/// a whole number >= 0 ("abc", "-2", "1.5").
[[nodiscard]] ThreadRequest resolve_threads(std::int64_t requested);

struct Execution {
  /// The most threads that work on one parallel loop. 0: the enclosing ExecutionScope's, else
  /// FOCAL_NUM_THREADS if set, else every CPU this process may run on. At most kMaxThreads
  /// (ExecutionScope clamps a larger count, warning through `warning`). Results are the same
  /// for any count.
  int threads = 0;
  /// Called on the calling thread as each stage begins and ends (none: nothing is reported).
  std::function<void(const Progress&)> progress{};
  /// Called on the calling thread as a parallel pass advances (the outermost loops of more than
  /// 1024 elements, on any thread count): when it starts (done 0), at most every 50 ms while it
  /// runs, and when it has finished (done == total). The pass belongs to the innermost stage
  /// that `progress` has begun. An exception thrown here stops the call, as a chunk's would.
  std::function<void(const PassProgress&)> pass_progress{};
  /// Called on the calling thread with each warning about the input or a choice made on it (a
  /// sentence without the file's name, which a caller that knows it puts before it).
  std::function<void(const std::string&)> warning{};
  /// Called on the calling thread with what the estimator decided (its plan), for a verbose log.
  std::function<void(const std::string&)> info{};
  /// When set, read between stages: true stops the call with Cancelled.
  const std::atomic<bool>* cancel = nullptr;
};

/// Makes a copy of `execution` the calling thread's current one (current_execution) for the
/// scope's lifetime; every focal call on this thread (and the parallel loops it starts on other
/// worker threads) then runs with its settings:
///
///     focal::ExecutionScope scope({.threads = 4});
///     auto normals = focal::vertex_normals(V, F);  // on 4 threads
///
/// Scopes nest: the innermost one wins, and a field it leaves at its default (a count of 0, no
/// callback, no cancel flag) is taken from the enclosing scope. The enclosing one is current
/// again when the inner one ends. No other thread is affected. Create and destroy scopes on one
/// thread in nested order (as locals).
class ExecutionScope {
 public:
  /// The count goes through resolve_threads (a clamp is reported through the execution's warning
  /// callback, else the enclosing scope's); FOCAL_NUM_THREADS is read by the outermost scope.
  /// \throw InvalidInput when the count is negative or FOCAL_NUM_THREADS is not a number.
  explicit ExecutionScope(const Execution& execution);
  ~ExecutionScope();
  ExecutionScope(const ExecutionScope&) = delete;
  ExecutionScope& operator=(const ExecutionScope&) = delete;

 private:
  Execution execution_;
  const Execution* enclosing_;
};

/// The calling thread's current Execution: that of its innermost ExecutionScope, or the
/// defaults (all zero, no callbacks) outside every scope. Inside a parallel loop's body, that of
/// the thread that started the loop.
[[nodiscard]] const Execution& current_execution();

}  // namespace focal
