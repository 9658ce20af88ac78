#pragma once
/// \file execution.h
/// How a call runs, apart from what it computes: threads, progress, messages and cancellation,
/// in one struct that the front door (focal/curvature.h) takes as EstimateOptions::execution.
/// Nothing here changes a result: every field gives the same bits for any setting.

#include <atomic>
#include <functional>
#include <string>
#include <string_view>

namespace focal {

/// A stage of a long call: reported when it begins (fraction 0) and when it ends (fraction 1).
struct Progress {
  std::string_view stage;  ///< "normals", "curvature", "cloud curvature", ...
  double fraction = 0.0;   ///< 0 at the start of the stage, 1 at its end
};

struct Execution {
  /// Worker threads. 0: FOCAL_NUM_THREADS if set, else every CPU this process may run on.
  /// Results are the same for any count.
  int threads = 0;
  /// Called on the calling thread as each stage begins and ends (none: nothing is reported).
  std::function<void(const Progress&)> progress;
  /// Called on the calling thread with each warning about the input or a choice made on it (a
  /// sentence without the file's name, which a caller that knows it puts before it).
  std::function<void(const std::string&)> warning;
  /// Called on the calling thread with what the estimator decided (its plan), for a verbose log.
  std::function<void(const std::string&)> info;
  /// When set, read between stages: true stops the call with Cancelled.
  const std::atomic<bool>* cancel = nullptr;
};

}  // namespace focal
