#pragma once
/// \file atomic_file.h
/// The one way focal writes a file (internal): into a temporary file beside the target, renamed
/// over the target only once every byte is written and the file closed without error. A failed
/// write (an exception, a write error, a full disk, a failed rename) removes the temporary file
/// and leaves an existing target as it was. Used by every writer: the mesh and table writers of
/// io/ and write_png (render/png_io.cpp).
///
/// A target that is a symbolic link is written through: the file the link points to is replaced
/// (the temporary file goes beside it) and the link is kept; a link to nothing is an IoError.
///
/// The temporary file is `.<name>.tmp-<16 hex digits>` in the target's folder (hidden, so that a
/// leftover after a crash does not look like output; the same folder, so that the rename is
/// atomic), created exclusively so that no other writer's file is reused. No fsync: the rename
/// protects against half-written files from failures in the process, not against power loss.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace focal::io_detail {

/// The longest temporary path (with its terminating zero) that a signal handler can remove.
inline constexpr std::size_t kMaxRegisteredPath = 4096;

/// Puts `path` in the table that the handlers of remove_temporary_files_on_signals
/// (focal/io/interrupted_writes.h) unlink; returns its slot, or -1 when the table is full or the
/// path too long (then a signal leaves that file, as without the handlers). Thread-safe.
int register_temporary(const char* path);
/// Takes slot `slot` (of register_temporary; -1: nothing) out of the table. Thread-safe.
void release_temporary(int slot);

/// A temporary file that becomes `target` on commit(). Destroyed without commit() (an exception
/// on the way), it closes and removes the temporary file; `target` is not touched. While it
/// exists, its path is in the table of register_temporary, so that a SIGINT or SIGTERM removes it
/// too (when the program installed remove_temporary_files_on_signals).
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
  /// Flushes and closes the file without renaming it (the first phase of AtomicFileGroup).
  /// \throw IoError naming the target on a write error.
  void finish();

  [[nodiscard]] const std::filesystem::path& target() const { return target_; }
  [[nodiscard]] const std::filesystem::path& temporary() const { return temporary_; }
  /// The temporary file has been renamed to the target (by its owner): do not remove it.
  void mark_committed() {
    committed_ = true;
    // Renamed: a signal now must not remove the path (nothing is there, or another writer's).
    release_temporary(slot_);
    slot_ = -1;
  }

 private:
  std::filesystem::path target_;
  std::filesystem::path temporary_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
  int slot_ = -1;  ///< of register_temporary
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

/// Writes the lines of items [0, count), append_line(out, i) for item i, formatted in parallel
/// blocks on `threads` threads (0: the default) and written in item order after whatever the
/// sink's buffer holds, so the bytes do not depend on the thread count.
void write_lines(OutputSink& sink, std::int64_t count, int threads,
                 const std::function<void(std::string&, std::int64_t)>& append_line);

/// Several files written all or nothing (a two-phase commit): while a group is open on a thread,
/// write_atomically on that thread writes and closes its temporary file but leaves the rename to
/// the group. commit() then moves the existing targets aside, renames every temporary file over
/// its target and removes the old files; if any step fails, every target gets its old file back
/// (or is removed when it did not exist) and the temporaries are removed. Destroyed without
/// commit() (an exception on the way) it removes the temporaries and touches no target.
/// Protects against failures in the process (a target that is a folder, a failed rename), not
/// against a crash during commit(), between the moves aside and the renames.
class AtomicFileGroup {
 public:
  AtomicFileGroup();
  ~AtomicFileGroup();
  AtomicFileGroup(const AtomicFileGroup&) = delete;
  AtomicFileGroup& operator=(const AtomicFileGroup&) = delete;

  /// Puts every file in place. \throw IoError naming the target that failed; then every target
  /// is as it was before.
  void commit();

  /// The group open on this thread, or nullptr.
  [[nodiscard]] static AtomicFileGroup* current();
  /// Takes a finished (AtomicFile::finish) file for commit().
  void adopt(std::unique_ptr<AtomicFile> file);

 private:
  std::vector<std::unique_ptr<AtomicFile>> files_;
  AtomicFileGroup* previous_;
};

/// Runs `body` on an OutputSink into a new AtomicFile for `path`, flushes it and commits (or,
/// inside an AtomicFileGroup, leaves the commit to the group).
/// \throw IoError naming `path` when the file cannot be created, written or renamed; whatever
/// `body` throws. In either case `path` is left as it was.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(OutputSink&)>& body);

}  // namespace focal::io_detail
