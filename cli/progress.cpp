#include "progress.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <utility>

namespace focal::cli {
namespace {

/// Lines alive, nested in stage order (stages begin and end on the command's thread).
std::atomic<int> g_depth{0};
constexpr auto kFirstDraw = std::chrono::seconds(1);
constexpr auto kRedraw = std::chrono::milliseconds(250);

/// The last pass the library reported (Execution::pass_progress, on the command's thread), read
/// by the watchers (relaxed: only a display reads them).
std::atomic<std::int64_t> g_pass_done{0};
std::atomic<std::int64_t> g_pass_total{0};
std::atomic<std::uint64_t> g_pass{0};

}  // namespace

void ProgressLine::report(const PassProgress& p) {
  g_pass_total.store(p.total, std::memory_order_relaxed);
  g_pass_done.store(p.done, std::memory_order_relaxed);
  g_pass.store(p.pass, std::memory_order_relaxed);
}

bool ProgressLine::terminal() { return isatty(STDERR_FILENO) == 1; }

std::string ProgressLine::text(const std::string& stage, double seconds, double fraction,
                               double pass_seconds) {
  char line[160];
  int n = std::snprintf(line, sizeof line, "%s: %.0f s", stage.c_str(), seconds);
  if (fraction >= 0.0 && n > 0 && static_cast<std::size_t>(n) < sizeof line) {
    n += std::snprintf(line + n, sizeof line - static_cast<std::size_t>(n), ", %.0f%% of a pass",
                       100.0 * fraction);
    // The rate of the pass so far: shown once it says something (5% done).
    if (fraction >= 0.05 && fraction < 1.0 && static_cast<std::size_t>(n) < sizeof line) {
      std::snprintf(line + n, sizeof line - static_cast<std::size_t>(n),
                    ", about %.0f s left of it", pass_seconds * (1.0 - fraction) / fraction);
    }
  }
  return line;
}

ProgressLine::ProgressLine(std::string stage)
    : stage_(std::move(stage)), depth_(++g_depth), start_(std::chrono::steady_clock::now()) {
  watcher_ = std::thread([this] { watch(); });
}

ProgressLine::~ProgressLine() {
  {
    const std::lock_guard lock(mutex_);
    done_ = true;
  }
  done_signal_.notify_one();
  watcher_.join();
  --g_depth;
  if (drawn_) std::fputs("\r\033[K", stderr);
}

void ProgressLine::watch() {
  std::unique_lock lock(mutex_);
  auto next = start_ + kFirstDraw;
  const std::uint64_t first_pass = g_pass.load(std::memory_order_relaxed);
  std::uint64_t pass = first_pass;
  auto pass_start = start_;
  while (!done_signal_.wait_until(lock, next, [this] { return done_; })) {
    next += kRedraw;
    if (g_depth.load() != depth_) continue;  // an inner stage draws its own line
    const auto now = std::chrono::steady_clock::now();
    const PassProgress p{g_pass_done.load(std::memory_order_relaxed),
                         g_pass_total.load(std::memory_order_relaxed),
                         g_pass.load(std::memory_order_relaxed)};
    if (p.pass != pass) pass = p.pass, pass_start = now;  // first seen now: a late start
    // Only a pass this stage started, and not finished, has a fraction of this stage's work.
    const double fraction =
        p.pass != first_pass && p.total > 0 && p.done < p.total ? p.fraction() : -1.0;
    const std::string line =
        text(stage_, std::chrono::duration<double>(now - start_).count(), fraction,
             std::chrono::duration<double>(now - pass_start).count());
    std::fprintf(stderr, "\r\033[K%s", line.c_str());
    std::fflush(stderr);
    drawn_ = true;
  }
}

}  // namespace focal::cli
