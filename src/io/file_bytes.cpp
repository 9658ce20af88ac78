#include "io/file_bytes.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <system_error>

#if defined(__unix__) || defined(__APPLE__)
#include <sys/mman.h>
#endif

#include "core/memory.h"
#include "focal/core/error.h"

namespace focal::io_detail {

void fail(const std::filesystem::path& path, const std::string& what) {
  throw IoError(path.string() + ": " + what);
}

void fail_at_line(const std::filesystem::path& path, std::size_t line, const std::string& what) {
  throw IoError(path.string() + ": line " + std::to_string(line) + ": " + what);
}

void fail_at_offset(const std::filesystem::path& path, std::size_t offset,
                    const std::string& what) {
  throw IoError(path.string() + ": byte offset " + std::to_string(offset) + ": " + what);
}

namespace {

/// Files from this size on are mapped: below it a read costs less than the mapping's setup.
constexpr std::uintmax_t kMapFrom = std::uintmax_t{1} << 20;

/// The first `size` bytes of `file` mapped read-only and faulted in at once, or nullptr where
/// mapping is not available or fails (the caller reads instead).
std::shared_ptr<const char> mapped(std::FILE* file, std::uintmax_t size) {
#if defined(__unix__) || defined(__APPLE__)
  int flags = MAP_PRIVATE;
#if defined(MAP_POPULATE)
  flags |= MAP_POPULATE;
#endif
  void* p = mmap(nullptr, static_cast<std::size_t>(size), PROT_READ, flags, fileno(file), 0);
  if (p == MAP_FAILED) return nullptr;
  const auto bytes = static_cast<std::size_t>(size);
  return {static_cast<const char*>(p), [bytes](const char* q) {
            munmap(const_cast<char*>(q), bytes);  // NOLINT: munmap takes void*
          }};
#else
  (void)file, (void)size;
  return nullptr;
#endif
}

}  // namespace

FileBytes read_whole_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) fail(path, "no such file");
  if (std::filesystem::is_directory(status)) fail(path, "is a directory, not a mesh file");
  // A FIFO would block until a writer appears and a device such as /dev/zero never ends; only a
  // regular file (or a link to one) has the fixed size the readers check counts against.
  if (!std::filesystem::is_regular_file(status)) {
    const char* kind = std::filesystem::is_fifo(status)             ? "a FIFO"
                       : std::filesystem::is_character_file(status) ? "a character device"
                       : std::filesystem::is_block_file(status)     ? "a block device"
                       : std::filesystem::is_socket(status)         ? "a socket"
                                                                    : "not a regular file";
    fail(path, std::string("is ") + kind + ", not a regular file (mesh files are read whole)");
  }

  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) fail(path, std::string("cannot open for reading: ") + std::strerror(errno));
  // Read into a buffer one byte larger than the reported size, so that a file that grew (or a
  // size query that is wrong, as for pipes) is noticed and the buffer extended.
  const auto size_hint = std::filesystem::file_size(path, ec);
  if (!ec && size_hint >= kMapFrom) {
    if (auto bytes = mapped(file, size_hint)) {
      std::fclose(file);  // the mapping stays valid without the descriptor
      return {std::move(bytes), static_cast<std::size_t>(size_hint)};
    }
  }
  std::size_t capacity = ec ? std::size_t{1} << 20 : static_cast<std::size_t>(size_hint) + 1;
  auto data = std::make_unique_for_overwrite<char[]>(capacity);
  std::size_t used = 0;
  for (;;) {
    used += std::fread(data.get() + used, 1, capacity - used, file);
    if (used < capacity) break;
    auto larger = std::make_unique_for_overwrite<char[]>(2 * capacity);
    std::memcpy(larger.get(), data.get(), used);
    data = std::move(larger);
    capacity *= 2;
  }
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) fail(path, "read error");
  return {std::move(data), used};
}

namespace {

/// check_count_fits and check_records_fit: `slack` bytes of the last element may be missing.
void check_elements_fit(const std::filesystem::path& path, std::string_view where,
                        std::uint64_t count, std::uint64_t min_bytes, std::uint64_t available,
                        std::uint64_t slack, std::string_view what) {
  if (min_bytes > 0 && count > (available + slack) / min_bytes) {
    fail(path, std::string(where) + ": header declares " + std::to_string(count) + " " +
                   std::string(what) + " but the " + std::to_string(available) +
                   " bytes that follow can hold at most " +
                   std::to_string((available + slack) / min_bytes));
  }
  if (count > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
    fail(path, std::string(where) + ": header declares " + std::to_string(count) + " " +
                   std::string(what) + ", more than 32-bit indices can address");
  }
}

}  // namespace

void check_count_fits(const std::filesystem::path& path, std::string_view where,
                      std::uint64_t count, std::uint64_t min_bytes, std::uint64_t available,
                      std::string_view what) {
  // The last element of a text file may lack its separator, hence the slack of 1.
  check_elements_fit(path, where, count, min_bytes, available, 1, what);
}

void check_records_fit(const std::filesystem::path& path, std::string_view where,
                       std::uint64_t count, std::uint64_t record_bytes, std::uint64_t available,
                       std::string_view what) {
  check_elements_fit(path, where, count, record_bytes, available, 0, what);
}

void require_memory_for(const std::filesystem::path& path, std::uint64_t count,
                        std::uint64_t bytes_each, std::string_view what) {
  const std::uint64_t available = detail::available_memory();
  // count < 2^31 (the checks above) and bytes_each is a few hundred at most: no overflow.
  const std::uint64_t needed = count * bytes_each;
  if (available == 0 || needed <= available) return;
  fail(path, "reading " + std::to_string(count) + " " + std::string(what) + " needs about " +
                 detail::memory_text(needed) + " of memory, more than the " +
                 detail::memory_text(available) + " this machine has available");
}

std::string quoted(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 2);
  out += '\'';
  out += text;
  out += '\'';
  return out;
}

std::string to_lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return out;
}

}  // namespace focal::io_detail
