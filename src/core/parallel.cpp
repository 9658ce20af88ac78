// The process-wide worker pool behind parallel_chunks (see parallel.h for why it exists), and
// the calling thread's current Execution (focal/core/execution.h) that sets its thread count.
#include "core/parallel.h"

#if defined(__linux__)
#include <sched.h>
#endif

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include "focal/core/error.h"
#include "focal/core/execution.h"

namespace focal {

namespace {
/// The innermost ExecutionScope's Execution on this thread (null: none); on a pool worker, that
/// of the loop it is working on.
thread_local const Execution* t_execution = nullptr;
}  // namespace

ExecutionScope::ExecutionScope(const Execution& execution)
    : execution_(execution), enclosing_(t_execution) {
  if (execution.threads < 0) throw InvalidInput("ExecutionScope: threads must be >= 0");
  if (enclosing_ != nullptr) {
    // Fields left at their defaults are the enclosing scope's.
    if (execution_.threads == 0) execution_.threads = enclosing_->threads;
    if (!execution_.progress) execution_.progress = enclosing_->progress;
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

/// One parallel_chunks call, living on its caller's stack until every worker that joined it
/// has left (Pool::run waits for that).
struct Job {
  std::int64_t chunks = 0;
  const std::function<void(std::int64_t)>* chunk = nullptr;
  int max_helpers = 0;  ///< workers that may join (threads - 1)
  /// The caller's current Execution: current on each worker while it takes chunks, so that a
  /// loop's body sees the settings of the thread that started the loop.
  const Execution* execution = nullptr;
  std::atomic<std::int64_t> next{0};
  int joined = 0;            ///< workers that joined; guarded by Pool::mutex
  int inside = 0;            ///< workers still working on it; guarded by Pool::mutex
  std::exception_ptr error;  ///< the first exception; guarded by error_mutex
  std::mutex error_mutex;
};

thread_local int t_slot = 0;   // worker_slot()
thread_local int t_depth = 0;  // > 0 while running chunks: a nested loop runs serially

/// Takes chunks of `job` until none is left, as worker `slot` of it.
void take_chunks(Job& job, int slot) {
  const int saved_slot = std::exchange(t_slot, slot);
  const Execution* saved_execution = std::exchange(t_execution, job.execution);
  ++t_depth;
  for (std::int64_t c; (c = job.next.fetch_add(1, std::memory_order_relaxed)) < job.chunks;) {
    try {
      (*job.chunk)(c);
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
  if (requested > 0) return requested;
  if (const int scoped = current_execution().threads; scoped > 0) return scoped;
  if (const char* env = std::getenv("FOCAL_NUM_THREADS")) {
    const int n = std::atoi(env);
    if (n > 0) return n;
  }
  static const int cpus = available_cpus();
  return cpus;
}

int worker_slot() { return t_slot; }

void parallel_chunks(std::int64_t chunks, int threads,
                     const std::function<void(std::int64_t)>& chunk) {
  const int t = thread_count(threads);
  if (chunks <= 0) return;
  if (t <= 1 || chunks == 1 || t_depth > 0) {
    // Serial, also for a loop inside a loop's body: its thread is already one of the team.
    ++t_depth;
    try {
      for (std::int64_t c = 0; c < chunks; ++c) chunk(c);
    } catch (...) {
      --t_depth;
      throw;
    }
    --t_depth;
    return;
  }
  Job job;
  job.chunks = chunks;
  job.chunk = &chunk;
  job.max_helpers = t - 1;
  job.execution = t_execution;
  Pool::instance().run(job);
}

}  // namespace focal::detail
