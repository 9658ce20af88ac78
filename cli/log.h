#pragma once
// Messages of the focal command on stderr: `Error:` / `Warning:` prefixes, and with -v the
// stage timings and summaries.

#include <chrono>
#include <string>

namespace focal::cli {

class Log {
 public:
  void set_verbose(bool v) { verbose_ = v; }
  [[nodiscard]] bool verbose() const { return verbose_; }
  void warning(const std::string& message) const;
  void info(const std::string& message) const;  // only with -v

 private:
  bool verbose_ = false;
};

/// Times one stage; with -v prints "  <name>: <ms> ms" when it ends.
class Stage {
 public:
  Stage(const Log& log, std::string name);
  ~Stage();
  Stage(const Stage&) = delete;
  Stage& operator=(const Stage&) = delete;

 private:
  const Log& log_;
  std::string name_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace focal::cli
