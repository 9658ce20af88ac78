#pragma once
// The one place where focal goes parallel. Every parallel loop gathers into per-element (or
// per-block) output slots (no scatter, no atomics), and the chunks of work have fixed boundaries
// whatever the thread count, so results are identical for any thread count.
//
// Why not `#pragma omp parallel for schedule(static)`: a static split waits at the end of every
// loop for the thread the OS descheduled, and GOMP's waiting threads spin on the core that
// thread needs (GOMP reads OMP_WAIT_POLICY / GOMP_SPINCOUNT only at process start, so a library
// cannot turn the spin off): on a loaded machine more threads could take longer than one. Here
// instead:
// - work is cut into many small chunks taken on demand, so a descheduled thread holds up at most
//   one chunk and the others take the rest;
// - every wait sleeps in the kernel (a condition variable), never spins: idle workers between
//   loops and the caller waiting for the last chunk leave their core to whoever needs it;
// - one process-wide pool of (CPUs - 1) workers serves every calling thread: focal never runs
//   more than #callers + CPUs - 1 threads however many threads call it at once
//   (docs/PERFORMANCE.md, "Threads"). The calling thread always works on its own loop, so a loop
//   finishes even when every worker is busy elsewhere (or absent, after fork()).
// - a loop started inside a loop's body runs on the calling thread (no nested teams).

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace focal {
struct PassProgress;
}

namespace focal::detail {

/// One pass of `total` steps reported through the calling thread's Execution::pass_progress (when
/// it has one): at the start, at most every 50 ms after that (advance), and at the end
/// (finish; not from the destructor, since the callback may throw Cancelled). parallel_chunks makes
/// each outermost loop one; work that runs as a sequence of short loops (a writer's batches) makes
/// one around them, so that it shows as one pass and not as many that a display sampling a few
/// times a second would see only at their start. Loops run inside a loop's body or while a
/// ReportedPass is alive on the thread are no pass of their own. Only for the calling thread: it
/// lives on its stack.
class ReportedPass {
 public:
  explicit ReportedPass(std::int64_t total);
  ~ReportedPass();
  ReportedPass(const ReportedPass&) = delete;
  ReportedPass& operator=(const ReportedPass&) = delete;
  [[nodiscard]] bool active() const { return callback_ != nullptr; }
  /// `done` of the pass's `total` steps are done.
  void advance(std::int64_t done);
  /// All `total` steps are done.
  void finish();

 private:
  static constexpr auto kPeriod = std::chrono::milliseconds(50);
  const std::function<void(const PassProgress&)>* callback_ = nullptr;
  std::int64_t total_;
  std::uint64_t pass_ = 0;
  std::chrono::steady_clock::time_point last_;
};

/// CPUs this process may run on (its affinity mask), at least 1.
int available_cpus();

/// Threads to use: `requested` if > 0 (at most kMaxThreads), else the current ExecutionScope's
/// threads if > 0 (focal/core/execution.h), else FOCAL_NUM_THREADS if set, else available_cpus().
/// At most this many threads work on one loop; fewer when the process-wide pool is busy.
int thread_count(int requested);

/// Index of the calling thread within the loop it is working on, in [0, thread_count(threads))
/// of that loop (0 on the caller, and on any thread outside a loop). For per-thread scratch
/// (PerThread in mesh/topology.h); never for results, which must not depend on it.
int worker_slot();

/// Runs chunk(c) for every c in [0, chunks) on up to `threads` threads (see thread_count):
/// the calling thread and pool workers take chunks in turn until none is left; returns when
/// all have run. Outside every loop's body (the outermost pass) and with more than one chunk,
/// its progress goes to the current Execution's pass_progress on the calling thread, on one
/// thread too. An exception thrown by a chunk stops the taking of further chunks and is
/// rethrown here (the first one, when several threads throw).
void parallel_chunks(std::int64_t chunks, int threads,
                     const std::function<void(std::int64_t)>& chunk);

/// Elements per chunk of parallel_for over n elements: about 256 chunks, 256 to 16384 elements
/// each. Depends on n only, never on the thread count.
inline std::int64_t parallel_grain(std::int64_t n) {
  return std::clamp<std::int64_t>(n / 256, 256, 16384);
}

/// Calls body(i) for i in [0, n) on `threads` threads (see thread_count), in chunks of
/// parallel_grain(n) taken on demand (one after the other on one thread: the same chunks, whose
/// progress is reported). A plain loop up to 1024 elements.
template <class Body>
void parallel_for(std::int64_t n, int threads, Body&& body) {
  if (n <= 1024) {
    for (std::int64_t i = 0; i < n; ++i) body(i);
    return;
  }
  const std::int64_t grain = parallel_grain(n);
  parallel_chunks((n + grain - 1) / grain, threads, [&](std::int64_t c) {
    const std::int64_t end = std::min(n, (c + 1) * grain);
    for (std::int64_t i = c * grain; i < end; ++i) body(i);
  });
}

/// Calls body(begin, end) for consecutive blocks [begin, end) of at most `block` elements that
/// cover [0, n), in parallel as parallel_for (one block per chunk). For loops that keep scratch
/// memory or a result per block; block boundaries do not depend on the thread count.
template <class Body>
void parallel_for_blocks(std::int64_t n, std::int64_t block, int threads, Body&& body) {
  const std::int64_t blocks = (n + block - 1) / block;
  if (n <= 1024) {
    for (std::int64_t b = 0; b < blocks; ++b) body(b * block, std::min(n, (b + 1) * block));
    return;
  }
  parallel_chunks(blocks, threads,
                  [&](std::int64_t b) { body(b * block, std::min(n, (b + 1) * block)); });
}

/// Asks Linux for transparent huge pages under [p, p + bytes) before it is first written: a
/// freshly allocated result is otherwise faulted in 4 KiB at a time (one page fault per 4 KiB
/// of the result). Only the whole 2 MiB pages inside the range
/// are advised; elsewhere, or where the kernel declines, nothing changes. Never affects results.
inline void advise_huge_pages([[maybe_unused]] const void* p, [[maybe_unused]] std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t{1} << 21;
  const auto first = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const auto last = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#endif
}

}  // namespace focal::detail
