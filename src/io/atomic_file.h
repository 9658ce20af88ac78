#pragma once
/// \file atomic_file.h
/// The one way focal writes a file (internal): into a temporary file beside the target, renamed
/// over the target only once every byte is written and the file closed without error. A failed
/// write (an exception, a write error, a full disk, a failed rename) removes the temporary file
/// and leaves an existing target as it was. Used by every writer: the mesh and table writers of
/// io/ and write_png (render/png_io.cpp).
///
/// The temporary file is `.<name>.tmp-<16 hex digits>` in the target's folder (hidden, so that a
/// leftover after a crash does not look like output; the same folder, so that the rename is
/// atomic), created exclusively so that no other writer's file is reused. No fsync: the rename
/// protects against half-written files from failures in the process, not against power loss.

#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>

namespace focal::io_detail {

/// A temporary file that becomes `target` on commit(). Destroyed without commit() (an exception
/// on the way), it closes and removes the temporary file; `target` is not touched.
class AtomicFile {
 public:
  /// Creates the temporary file.
  /// \throw IoError naming `target` when it has no file name or the file cannot be created.
  explicit AtomicFile(const std::filesystem::path& target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// The open temporary file (binary mode), for writers that take a FILE* (libpng).
  [[nodiscard]] std::FILE* file() const { return file_; }
  /// Writes `bytes` bytes from `data`. \throw IoError naming the target on failure.
  void write(const char* data, std::size_t bytes);

  /// Flushes and closes the file and renames it to the target.
  /// \throw IoError naming the target on a write error or a failed rename (the temporary file is
  /// removed by the destructor).
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temporary_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

/// Buffered output to an AtomicFile, for writers that format into memory.
class OutputSink {
 public:
  explicit OutputSink(AtomicFile& file) : file_(file) {}
  /// The buffer to append to; call maybe_flush() now and then.
  std::string& buffer() { return buffer_; }
  void maybe_flush() {
    if (buffer_.size() >= kFlushBytes) flush();
  }
  /// Writes the buffer out. \throw IoError naming the target on failure.
  void flush();
  /// Writes the buffer out, then `bytes` bytes from `data` without copying them into the buffer
  /// (for writers that format large blocks themselves). \throw IoError as flush().
  void write(const char* data, std::size_t bytes);

 private:
  static constexpr std::size_t kFlushBytes = std::size_t{1} << 20;
  AtomicFile& file_;
  std::string buffer_;
};

/// Runs `body` on an OutputSink into a new AtomicFile for `path`, flushes it and commits.
/// \throw IoError naming `path` when the file cannot be created, written or renamed; whatever
/// `body` throws. In either case `path` is left as it was.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(OutputSink&)>& body);

}  // namespace focal::io_detail
