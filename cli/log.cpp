#include "log.h"

#include <cstdio>

namespace focal::cli {

std::string one_line(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n";
    } else if (byte < 0x20 || byte == 0x7f) {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", byte);
      out += hex;
    } else {
      out += c;
    }
  }
  return out;
}

void Log::warning(const std::string& message) const {
  std::fprintf(stderr, "Warning: %s\n", one_line(message).c_str());
}

void Log::info(const std::string& message) const {
  if (verbose_) std::fprintf(stderr, "%s\n", message.c_str());
}

Stage::Stage(const Log& log, std::string name)
    : log_(log), name_(std::move(name)), start_(std::chrono::steady_clock::now()) {
  if (log_.verbose()) watcher_ = std::thread([this] { report_progress(); });
}

void Stage::report_progress() {
  std::unique_lock lock(mutex_);
  auto next = start_ + kProgressPeriod;
  while (!done_signal_.wait_until(lock, next, [this] { return done_; })) {
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::fprintf(stderr, "  %-22s running for %.0f s\n", (name_ + ":").c_str(), s);
    next += kProgressPeriod;
  }
}

Stage::~Stage() {
  if (!log_.verbose()) return;
  {
    const std::lock_guard lock(mutex_);
    done_ = true;
  }
  done_signal_.notify_one();
  watcher_.join();
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr, "  %-22s %9.1f ms\n", (name_ + ":").c_str(), ms);
}

}  // namespace focal::cli
