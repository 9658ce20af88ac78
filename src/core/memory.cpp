#include "core/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "focal/core/error.h"

namespace focal::detail {
namespace {

/// The number in the first line of `path` (0 when unreadable or "max").
std::uint64_t number_in(const char* path) {
  std::ifstream in(path);
  std::uint64_t n = 0;
  if (!(in >> n)) return 0;
  return n;
}

}  // namespace

std::uint64_t available_memory() {
  std::uint64_t available = 0;
  std::ifstream meminfo("/proc/meminfo");
  for (std::string line; std::getline(meminfo, line);) {
    unsigned long long kb = 0;
    if (std::sscanf(line.c_str(), "MemAvailable: %llu kB", &kb) == 1) {
      available = static_cast<std::uint64_t>(kb) * 1024;
      break;
    }
  }
  // An address-space limit (ulimit -v) caps what can be allocated, whatever is free.
  rlimit address_space{};
  if (getrlimit(RLIMIT_AS, &address_space) == 0 && address_space.rlim_cur != RLIM_INFINITY) {
    std::ifstream statm("/proc/self/statm");
    std::uint64_t pages = 0;
    statm >> pages;
    const std::uint64_t used = pages * static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE));
    const auto cap = static_cast<std::uint64_t>(address_space.rlim_cur);
    const std::uint64_t left = cap > used ? cap - used : 1;
    available = available == 0 ? left : std::min(available, left);
  }
  const std::uint64_t limit = number_in("/sys/fs/cgroup/memory.max");
  if (limit > 0) {
    const std::uint64_t used = number_in("/sys/fs/cgroup/memory.current");
    const std::uint64_t left = limit > used ? limit - used : 0;
    available = available == 0 ? left : std::min(available, left);
  }
  return available;
}

std::string memory_text(std::uint64_t bytes) {
  char text[32];
  const double gb = static_cast<double>(bytes) / 1e9;
  if (gb >= 1.0) {
    std::snprintf(text, sizeof text, "%.3g GB", gb);
  } else {
    std::snprintf(text, sizeof text, "%.3g MB", static_cast<double>(bytes) / 1e6);
  }
  return text;
}

void require_memory(std::uint64_t bytes, const std::string& what) {
  const std::uint64_t available = available_memory();
  if (available == 0 || bytes <= available) return;
  throw InvalidInput(what + " needs about " + memory_text(bytes) + " of memory, more than the " +
                     memory_text(available) + " this machine has available");
}

}  // namespace focal::detail
