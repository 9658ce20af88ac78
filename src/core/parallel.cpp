// The process-wide worker pool behind parallel_chunks (see parallel.h for why it exists), and
// the calling thread's current Execution (focal/core/execution.h) that sets its thread count.
#include "core/parallel.h"

#if defined(__linux__)
#include <sched.h>
#endif

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <exception>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "focal/core/error.h"
#include "focal/core/execution.h"

namespace focal {

namespace {
/// The innermost ExecutionScope's Execution on this thread (null: none); on a pool worker, that
/// of the loop it is working on.
thread_local const Execution* t_execution = nullptr;

/// `requested` > 0 clamped to kMaxThreads; `what` names it in the warning.
ThreadRequest clamped(std::int64_t requested, const std::string& what) {
  ThreadRequest r;
  r.threads = static_cast<int>(std::min<std::int64_t>(requested, kMaxThreads));
  if (requested > kMaxThreads) {
    r.warning = what + ": " + std::to_string(requested) + " threads asked for, more than the " +
                std::to_string(kMaxThreads) + " focal uses (the pool has one per CPU, here " +
                std::to_string(detail::available_cpus()) + "): using " +
                std::to_string(kMaxThreads);
  }
  return r;
}

/// FOCAL_NUM_THREADS resolved (0 when unset, empty or 0). \throw InvalidInput when it is not a
/// whole number >= 0.
ThreadRequest environment_threads() {
  const char* env = std::getenv("FOCAL_NUM_THREADS");
  if (env == nullptr || *env == '\0') return {};
  const std::string_view text(env);
  std::int64_t n = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), n);
  if (error == std::errc::result_out_of_range && text.front() != '-') {
    n = std::numeric_limits<std::int64_t>::max();  // all digits, too many: clamped below
  } else if (error != std::errc{} || end != text.data() + text.size() || n < 0) {
    throw InvalidInput("FOCAL_NUM_THREADS='" + std::string(text) +
                       "' is not a thread count (a whole number >= 0; 0 or unset: every CPU)");
  }
  return clamped(n, "FOCAL_NUM_THREADS");
}

}  // namespace

ThreadRequest resolve_threads(std::int64_t requested) {
  if (requested < 0) {
    throw InvalidInput("threads must be >= 0 (0: every CPU), got " + std::to_string(requested));
  }
  if (requested == 0) return environment_threads();
  return clamped(requested, "threads");
}

ExecutionScope::ExecutionScope(const Execution& execution)
    : execution_(execution), enclosing_(t_execution) {
  // The outermost scope also reads FOCAL_NUM_THREADS, so that a bad value is an error at the
  // call rather than a thread count silently ignored.
  if (execution.threads != 0 || enclosing_ == nullptr) {
    const ThreadRequest r = resolve_threads(execution.threads);
    execution_.threads = r.threads;
    if (!r.warning.empty()) {
      const auto& warn = execution.warning       ? execution.warning
                         : enclosing_ != nullptr ? enclosing_->warning
                                                 : execution.warning;
      if (warn) warn(r.warning);
    }
  }
  if (enclosing_ != nullptr) {
    // Fields left at their defaults are the enclosing scope's.
    if (execution_.threads == 0) execution_.threads = enclosing_->threads;
    if (!execution_.progress) execution_.progress = enclosing_->progress;
    if (!execution_.pass_progress) execution_.pass_progress = enclosing_->pass_progress;
    if (!execution_.warning) execution_.warning = enclosing_->warning;
    if (!execution_.info) execution_.info = enclosing_->info;
    if (execution_.cancel == nullptr) execution_.cancel = enclosing_->cancel;
  }
  t_execution = &execution_;
}

ExecutionScope::~ExecutionScope() { t_execution = enclosing_; }

const Execution& current_execution() {
  static const Execution defaults;
  return t_execution != nullptr ? *t_execution : defaults;
}

}  // namespace focal

namespace focal::detail {

namespace {

thread_local int t_depth = 0;  // > 0 while running chunks: a nested loop runs serially

thread_local int t_reported_passes = 0;  // ReportedPass objects alive on this thread

/// One parallel_chunks call, living on its caller's stack until every worker that joined it
/// has left (Pool::run waits for that).
struct Job {
  std::int64_t chunks = 0;
  const std::function<void(std::int64_t)>* chunk = nullptr;
  int max_helpers = 0;  ///< workers that may join (threads - 1)
  /// The caller's current Execution: current on each worker while it takes chunks, so that a
  /// loop's body sees the settings of the thread that started the loop.
  const Execution* execution = nullptr;
  ReportedPass* reporter = nullptr;  ///< the caller's, told after each of its chunks
  std::atomic<std::int64_t> next{0};
  std::atomic<std::int64_t> done{0};  ///< chunks finished, for the reporter
  int joined = 0;                     ///< workers that joined; guarded by Pool::mutex
  int inside = 0;                     ///< workers still working on it; guarded by Pool::mutex
  std::exception_ptr error;           ///< the first exception; guarded by error_mutex
  std::mutex error_mutex;
};

thread_local int t_slot = 0;  // worker_slot()

/// Takes chunks of `job` until none is left, as worker `slot` of it.
void take_chunks(Job& job, int slot) {
  const int saved_slot = std::exchange(t_slot, slot);
  const Execution* saved_execution = std::exchange(t_execution, job.execution);
  ++t_depth;
  for (std::int64_t c; (c = job.next.fetch_add(1, std::memory_order_relaxed)) < job.chunks;) {
    try {
      (*job.chunk)(c);
      const std::int64_t done = job.done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (slot == 0 && job.reporter != nullptr) job.reporter->advance(done);
    } catch (...) {
      const std::scoped_lock lock(job.error_mutex);
      if (!job.error) job.error = std::current_exception();
      job.next.store(job.chunks, std::memory_order_relaxed);  // take no further chunks
    }
  }
  --t_depth;
  t_execution = saved_execution;
  t_slot = saved_slot;
}

/// CPUs - 1 workers, started on first use and never stopped (a static destructor joining them
/// could run while another static's destructor still uses focal). Workers sleep on a condition
/// variable whenever no job is queued: nothing spins.
class Pool {
 public:
  static Pool& instance() {
    static Pool* pool = new Pool(available_cpus() - 1);
    return *pool;
  }

  void run(Job& job) {
    job.max_helpers = std::min(job.max_helpers, workers_);
    if (job.max_helpers > 0) {
      {
        const std::scoped_lock lock(mutex_);
        queue_.push_back(&job);
      }
      // Wake no more workers than there are chunks for besides the caller's first one.
      const auto wake = std::min<std::int64_t>(job.max_helpers, job.chunks - 1);
      for (std::int64_t i = 0; i < wake; ++i) work_.notify_one();
    }
    take_chunks(job, 0);
    if (job.max_helpers > 0) {
      std::unique_lock lock(mutex_);
      // All chunks are taken: let no further worker join, then wait (asleep) for those inside.
      if (const auto it = std::find(queue_.begin(), queue_.end(), &job); it != queue_.end()) {
        queue_.erase(it);
      }
      done_.wait(lock, [&] { return job.inside == 0; });
    }
    if (job.error) std::rethrow_exception(job.error);
  }

 private:
  explicit Pool(int workers) : workers_(std::max(0, workers)) {
    for (int i = 0; i < workers_; ++i) std::thread([this] { work(); }).detach();
  }

  [[noreturn]] void work() {
    std::unique_lock lock(mutex_);
    for (;;) {
      work_.wait(lock, [&] { return !queue_.empty(); });
      Job& job = *queue_.front();
      const int slot = ++job.joined;
      ++job.inside;
      if (job.joined >= job.max_helpers) queue_.pop_front();
      lock.unlock();
      take_chunks(job, slot);
      lock.lock();
      if (--job.inside == 0) done_.notify_all();
    }
  }

  int workers_;
  std::mutex mutex_;
  std::condition_variable work_;  ///< a job was queued
  std::condition_variable done_;  ///< a worker left a job
  std::deque<Job*> queue_;        ///< jobs that workers may still join, oldest first
};

}  // namespace

int available_cpus() {
#if defined(__linux__)
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
#endif
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

int thread_count(int requested) {
  if (requested > 0) return std::min(requested, kMaxThreads);
  if (const int scoped = current_execution().threads; scoped > 0) return scoped;
  if (const int env = environment_threads().threads; env > 0) return env;
  static const int cpus = available_cpus();
  return cpus;
}

int worker_slot() { return t_slot; }

void parallel_chunks(std::int64_t chunks, int threads,
                     const std::function<void(std::int64_t)>& chunk) {
  const int t = thread_count(threads);
  if (chunks <= 0) return;
  ReportedPass reporter(chunks);
  if (t <= 1 || chunks == 1 || t_depth > 0) {
    // Serial, also for a loop inside a loop's body: its thread is already one of the team.
    ++t_depth;
    try {
      for (std::int64_t c = 0; c < chunks; ++c) {
        chunk(c);
        reporter.advance(c + 1);
      }
    } catch (...) {
      --t_depth;
      throw;
    }
    --t_depth;
    reporter.finish();
    return;
  }
  Job job;
  job.chunks = chunks;
  job.chunk = &chunk;
  job.max_helpers = t - 1;
  job.execution = t_execution;
  if (reporter.active()) job.reporter = &reporter;
  Pool::instance().run(job);
  reporter.finish();
}

ReportedPass::ReportedPass(std::int64_t total) : total_(total) {
  // Only the outermost: a loop inside a loop's body, or inside another reported pass, is a part
  // of that pass, not a pass of its own.
  if (t_depth == 0 && t_reported_passes == 0 && total > 1 && t_execution != nullptr &&
      t_execution->pass_progress) {
    callback_ = &t_execution->pass_progress;
    static std::atomic<std::uint64_t> passes{0};
    pass_ = passes.fetch_add(1, std::memory_order_relaxed) + 1;
    last_ = std::chrono::steady_clock::now();
    (*callback_)({0, total_, pass_});
  }
  ++t_reported_passes;
}

ReportedPass::~ReportedPass() { --t_reported_passes; }

void ReportedPass::finish() {
  if (callback_ != nullptr) (*callback_)({total_, total_, pass_});
}

void ReportedPass::advance(std::int64_t done) {
  if (callback_ == nullptr) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < kPeriod) return;
  last_ = now;
  (*callback_)({done, total_, pass_});
}

}  // namespace focal::detail
