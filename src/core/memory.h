#pragma once
// Memory checked before large allocations: a request the machine cannot hold is a clear error
// before anything is allocated, rather than a process that swaps, is killed by the OOM killer or
// fails deep inside a driver.

#include <cstdint>
#include <string>

namespace focal::detail {

/// Bytes this process can still allocate without swapping: the smallest of MemAvailable
/// (/proc/meminfo), what an address-space limit (ulimit -v) leaves over the process's size, and
/// what the cgroup's memory.max leaves over memory.current (a container's limit); 0 when none is
/// known (not Linux).
[[nodiscard]] std::uint64_t available_memory();

/// "12.3 GB" (decimal units, three significant digits).
[[nodiscard]] std::string memory_text(std::uint64_t bytes);

/// \throw InvalidInput "<what> needs about <bytes>, more than the <available> this machine has
/// available" when `bytes` exceeds available_memory() (nothing when that is unknown).
void require_memory(std::uint64_t bytes, const std::string& what);

}  // namespace focal::detail
