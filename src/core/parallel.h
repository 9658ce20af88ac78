#pragma once
// The one place where focal goes parallel. Every parallel loop gathers into per-element output
// slots (no scatter, no atomics), so results are identical for any thread count.

#include <omp.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

namespace focal::detail {

/// Threads to use: `requested` if > 0, else FOCAL_NUM_THREADS if set, else all hardware threads.
inline int thread_count(int requested) {
  if (requested > 0) return requested;
  if (const char* env = std::getenv("FOCAL_NUM_THREADS")) {
    const int n = std::atoi(env);
    if (n > 0) return n;
  }
  return omp_get_max_threads();
}

/// Calls body(i) for i in [0, n) on `threads` threads (see thread_count) in static chunks.
template <class Body>
void parallel_for(std::int64_t n, int threads, Body&& body) {
  const int t = thread_count(threads);
#pragma omp parallel for schedule(static) num_threads(t) if (t > 1 && n > 1024)
  for (std::int64_t i = 0; i < n; ++i) body(i);
}

/// Calls body(begin, end) for consecutive blocks [begin, end) of at most `block` elements that
/// cover [0, n), in parallel as parallel_for. For loops that keep scratch memory per block
/// rather than per element; block boundaries do not depend on the thread count.
template <class Body>
void parallel_for_blocks(std::int64_t n, std::int64_t block, int threads, Body&& body) {
  const std::int64_t blocks = (n + block - 1) / block;
  const int t = thread_count(threads);
#pragma omp parallel for schedule(static) num_threads(t) if (t > 1 && n > 1024)
  for (std::int64_t b = 0; b < blocks; ++b) body(b * block, std::min(n, (b + 1) * block));
}

/// Asks Linux for transparent huge pages under [p, p + bytes) before it is first written: a
/// freshly allocated result is otherwise faulted in 4 KiB at a time (at 1M vertices the fit's
/// 97 MB cost ~24K page faults, a fifth of its time). Only the whole 2 MiB pages inside the range
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
