#pragma once
// The progress line of a long stage on a terminal: after a stage has run for a second, one line
// on stderr, rewritten four times a second, with the stage, the seconds it has run, and, while a
// parallel pass of the library runs, the fraction of it done and the time that pass has left
// (Execution::pass_progress, which the command's outermost scope sends to report()). Erased when
// the stage ends. Only when stderr is a terminal (never on pipes or files) and neither --quiet nor
// -v (which prints its own lines) was given.

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "focal/core/execution.h"

namespace focal::cli {

class ProgressLine {
 public:
  /// Starts the watcher of `stage`.
  explicit ProgressLine(std::string stage);
  /// Stops it, and erases its line when one was drawn.
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// Takes the library's latest report of a parallel pass (Execution::pass_progress), which the
  /// line of the innermost stage shows.
  static void report(const PassProgress& p);

  /// Whether stderr is a terminal (where the line may be drawn).
  [[nodiscard]] static bool terminal();

  /// The line's text: "<stage>: <s> s" and, for a pass `fraction` done (< 0: none known) that
  /// has run `pass_seconds`, ", <p>% of a pass, about <t> s left of it".
  [[nodiscard]] static std::string text(const std::string& stage, double seconds, double fraction,
                                        double pass_seconds);

 private:
  void watch();

  std::string stage_;
  int depth_;  ///< of nested lines: only the innermost draws
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable done_signal_;
  bool done_ = false;
  bool drawn_ = false;
  std::thread watcher_;
};

}  // namespace focal::cli
