#pragma once
// Messages of the focal command on stderr: `Error:` / `Warning:` prefixes, and with -v the
// stage timings and summaries.

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "focal/core/execution.h"
#include "progress.h"

namespace focal::cli {

/// `text` with control characters escaped (a newline as \n, others as \xNN), so that a file name
/// holding them cannot split an `Error:` or `Warning:` line.
[[nodiscard]] std::string one_line(const std::string& text);

class Log {
 public:
  void set_verbose(bool v) { verbose_ = v; }
  [[nodiscard]] bool verbose() const { return verbose_; }
  void set_quiet(bool q) { quiet_ = q; }
  /// Whether long stages draw a progress line (progress.h): stderr is a terminal, no --quiet,
  /// no -v.
  [[nodiscard]] bool progress() const {
    return !quiet_ && !verbose_ && ProgressLine::terminal();
  }
  void warning(const std::string& message) const;
  void info(const std::string& message) const;  // only with -v

 private:
  bool verbose_ = false;
  bool quiet_ = false;
};

/// Times one stage; with -v prints "  <name>: <ms> ms" when it ends, and on long runs a line
/// "  <name>: running for <s> s" every second until then (a watcher thread, started only with
/// -v, so that a 10 M-vertex run shows it is alive without the library knowing about the log);
/// without -v, on a terminal, the progress line of progress.h.
class Stage {
 public:
  Stage(const Log& log, std::string name);
  ~Stage();
  Stage(const Stage&) = delete;
  Stage& operator=(const Stage&) = delete;

  /// Seconds between the progress lines of a long stage.
  static constexpr std::chrono::seconds kProgressPeriod{1};

 private:
  void report_progress();

  const Log& log_;
  std::string name_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable done_signal_;
  bool done_ = false;
  std::thread watcher_;
  std::optional<ProgressLine> progress_;
};

/// The library's execution callbacks that print through `log` (the thread count is the
/// command's ExecutionScope's, from --threads): each stage a Stage (timed with
/// -v), each warning a `Warning: <name>: ...` line, each piece of information a -v line.
/// The returned callbacks hold a reference to `log`, which must outlive them.
[[nodiscard]] Execution execution_for(const Log& log, const std::string& name);

}  // namespace focal::cli
