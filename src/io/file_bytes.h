#pragma once
/// \file file_bytes.h
/// A file read whole into memory, and the IoError messages of the readers and writers that name
/// the file and the place in it (line, byte offset), with the checks of declared counts against
/// the bytes there are.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

namespace focal::io_detail {

/// Throws IoError("<path>: <what>").
[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what);
/// Throws IoError("<path>: line <line>: <what>").
[[noreturn]] void fail_at_line(const std::filesystem::path& path, std::size_t line,
                               const std::string& what);
/// Throws IoError("<path>: byte offset <offset>: <what>").
[[noreturn]] void fail_at_offset(const std::filesystem::path& path, std::size_t offset,
                                 const std::string& what);

/// A file's bytes in memory: a buffer the file was read into, or the file mapped read-only.
/// A buffer is not zero-filled before the read writes it (a std::string was: a pass over the
/// whole file of its own, ~80 MB for a 1M-vertex PLY).
class FileBytes {
 public:
  FileBytes(std::unique_ptr<char[]> data, std::size_t size)
      : data_(data.release(), std::default_delete<char[]>()), size_(size) {}
  /// Bytes owned by `owner` (a mapping, released with it).
  FileBytes(std::shared_ptr<const char> owner, std::size_t size)
      : data_(std::move(owner)), size_(size) {}
  [[nodiscard]] std::string_view view() const { return {data_.get(), size_}; }
  operator std::string_view() const { return view(); }  // NOLINT: parsers take string_view

 private:
  std::shared_ptr<const char> data_;
  std::size_t size_;
};

/// The whole file in memory, contiguous for the parsers: a regular file of 1 MiB or more mapped
/// (its pages are the page cache's: neither copied nor first-touched in a buffer of our own),
/// a smaller one, or one that cannot be mapped, read in one read. A mapped file must not be
/// shortened while it is parsed (as for any reader of a file another process rewrites).
/// \throw IoError when the path is missing, a directory or unreadable.
[[nodiscard]] FileBytes read_whole_file(const std::filesystem::path& path);

/// Throws IoError unless `count` elements of at least `min_bytes` each fit in `available` bytes.
/// Called before anything is allocated for a count declared in a file header, so that a header
/// claiming 1e12 vertices is rejected instead of exhausting memory. `where` is the place the
/// elements start ("line 12", "byte offset 345"), for the message.
void check_count_fits(const std::filesystem::path& path, std::string_view where,
                      std::uint64_t count, std::uint64_t min_bytes, std::uint64_t available,
                      std::string_view what);

/// The same for binary records of exactly `record_bytes` each, which must all be there (a text
/// file's last element may lack its separator, a binary record may not lack its last byte).
void check_records_fit(const std::filesystem::path& path, std::string_view where,
                       std::uint64_t count, std::uint64_t record_bytes, std::uint64_t available,
                       std::string_view what);

/// Bytes a vertex takes in a Mesh (its row of V), its normal (a row of N) and a triangle (a row
/// of F and its face_source), for require_memory_for.
inline constexpr std::uint64_t kVertexBytes = 3 * sizeof(double);
inline constexpr std::uint64_t kNormalBytes = 3 * sizeof(double);
inline constexpr std::uint64_t kTriangleBytes = 3 * sizeof(std::int32_t) + sizeof(int);

/// Throws IoError "<path>: reading <count> <what> needs about <bytes> of memory, more than the
/// <available> this machine has available" when `count` elements taking `bytes_each` bytes once
/// read (the arrays a reader fills for them) exceed detail::available_memory(). Called before a
/// reader allocates for a declared count, after check_count_fits / check_records_fit, so that a
/// file that is merely larger than the machine's memory fails with what it needs instead of an
/// allocation failure (or the OOM killer) deep in the read.
void require_memory_for(const std::filesystem::path& path, std::uint64_t count,
                        std::uint64_t bytes_each, std::string_view what);

/// `'text'`, for messages. (Also avoids "'" + std::string temporaries, on which GCC 12 gives a
/// false -Wrestrict warning.)
[[nodiscard]] std::string quoted(std::string_view text);

/// Lower-case ASCII copy.
[[nodiscard]] std::string to_lower(std::string_view s);

}  // namespace focal::io_detail
