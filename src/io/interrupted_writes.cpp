// The table of temporary files being written (atomic_file.h registers each AtomicFile's) and the
// signal handler that removes them (focal/io/interrupted_writes.h).
#include "focal/io/interrupted_writes.h"

#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstring>

#include "io/atomic_file.h"

namespace focal {
namespace io_detail {
namespace {

/// One temporary path. `state`: 0 free, 1 being filled or emptied, 2 armed (the handler may
/// read `path`). The handler reads only armed slots, and a slot's path is written only while
/// it is not armed, so the handler never sees a half-written path.
struct Slot {
  std::atomic<int> state{0};
  char path[kMaxRegisteredPath];
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads the states");

/// Enough for every file of one run (a focal mesh pair, a truth table, a tile's outputs);
/// a write beyond it is simply not removed on a signal (as before this table).
std::array<Slot, 64> g_slots;

}  // namespace

int register_temporary(const char* path) {
  const std::size_t length = std::strlen(path);
  if (length >= kMaxRegisteredPath) return -1;
  for (std::size_t i = 0; i < g_slots.size(); ++i) {
    int expected = 0;
    if (g_slots[i].state.compare_exchange_strong(expected, 1)) {
      std::memcpy(g_slots[i].path, path, length + 1);
      g_slots[i].state.store(2);
      return static_cast<int>(i);
    }
  }
  return -1;
}

void release_temporary(int slot) {
  if (slot < 0 || slot >= static_cast<int>(g_slots.size())) return;
  g_slots[static_cast<std::size_t>(slot)].state.store(0);
}

}  // namespace io_detail

namespace {

void remove_temporaries_and_reraise(int signal_number) {
  for (auto& slot : io_detail::g_slots) {
    if (slot.state.load() == 2) unlink(slot.path);
  }
  // The default action, so that the process ends by this signal (exit status 128 + number).
  struct sigaction action{};
  action.sa_handler = SIG_DFL;
  sigemptyset(&action.sa_mask);
  sigaction(signal_number, &action, nullptr);
  raise(signal_number);
}

}  // namespace

void remove_temporary_files_on_signals() {
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction current{};
    if (sigaction(signal_number, nullptr, &current) != 0) continue;
    if ((current.sa_flags & SA_SIGINFO) != 0 || current.sa_handler != SIG_DFL) continue;
    struct sigaction action{};
    action.sa_handler = remove_temporaries_and_reraise;
    sigemptyset(&action.sa_mask);
    // The other signals wait while the table is read, so that a second one does not cut it short.
    sigaddset(&action.sa_mask, SIGINT);
    sigaddset(&action.sa_mask, SIGTERM);
    sigaddset(&action.sa_mask, SIGHUP);
    sigaction(signal_number, &action, nullptr);
  }
}

}  // namespace focal
