#include "log.h"

#include <cstdio>
#include <memory>
#include <vector>

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
  if (progress()) std::fputs("\r\033[K", stderr);  // not after a progress line's text
  std::fprintf(stderr, "Warning: %s\n", one_line(message).c_str());
}

void Log::info(const std::string& message) const {
  if (verbose_) std::fprintf(stderr, "%s\n", message.c_str());
}

Stage::Stage(const Log& log, std::string name)
    : log_(log), name_(std::move(name)), start_(std::chrono::steady_clock::now()) {
  if (log_.verbose()) watcher_ = std::thread([this] { report_progress(); });
  if (log_.progress()) progress_.emplace(name_);
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

Execution execution_for(const Log& log, const std::string& name) {
  Execution e;
  // Stages begin and end in nesting order, on the calling thread.
  auto stages = std::make_shared<std::vector<std::unique_ptr<Stage>>>();
  e.progress = [&log, stages](const Progress& p) {
    if (p.fraction == 0.0) {
      stages->push_back(std::make_unique<Stage>(log, std::string(p.stage)));
    } else if (p.fraction == 1.0 && !stages->empty()) {
      stages->pop_back();
    }
  };
  e.warning = [&log, name](const std::string& message) { log.warning(name + ": " + message); };
  e.info = [&log](const std::string& message) { log.info(message); };
  return e;
}

}  // namespace focal::cli
