#include "log.h"

#include <cstdio>

namespace focal::cli {

void Log::warning(const std::string& message) const {
  std::fprintf(stderr, "Warning: %s\n", message.c_str());
}

void Log::info(const std::string& message) const {
  if (verbose_) std::fprintf(stderr, "%s\n", message.c_str());
}

Stage::Stage(const Log& log, std::string name)
    : log_(log), name_(std::move(name)), start_(std::chrono::steady_clock::now()) {}

Stage::~Stage() {
  if (!log_.verbose()) return;
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr, "  %-22s %9.1f ms\n", (name_ + ":").c_str(), ms);
}

}  // namespace focal::cli
