#include "io/atomic_file.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <random>
#include <system_error>

#include "core/parallel.h"
#include "focal/io/mesh_io.h"
#include "io/file_bytes.h"

namespace focal {
namespace io_detail {
namespace {

/// A name for the temporary file that no other writer (thread or process) picks at the same time.
std::filesystem::path temporary_path_for(const std::filesystem::path& path) {
  static std::atomic<std::uint64_t> counter{0};
  static const std::uint64_t seed = std::random_device{}();
  const std::uint64_t tag = seed * 0x9E3779B97F4A7C15ull + counter.fetch_add(1);
  char hex[17];
  const auto result = std::to_chars(hex, hex + 16, tag, 16);
  std::string name = ".";  // hidden, so that a crash leftover does not look like output
  name += path.filename().string();
  name += ".tmp-";
  name.append(hex, result.ptr);
  return path.parent_path() / name;
}

/// Opens a new temporary file; "x" makes the create exclusive so no existing file is reused.
/// Its path is in the signal handler's table (`slot`) before the file exists, so that no signal
/// can come between the two and leave a file the handler does not know of (unlinking a path
/// not yet created is harmless).
std::FILE* open_temporary(const std::filesystem::path& path, std::filesystem::path& temp,
                          int& slot) {
  for (int attempt = 0; attempt < 16; ++attempt) {
    temp = temporary_path_for(path);
    slot = register_temporary(temp.c_str());
    std::FILE* file = std::fopen(temp.c_str(), "wbx");
    if (file != nullptr) return file;
    const int saved_errno = errno;
    release_temporary(slot);  // not ours: another file of that name, or none
    slot = -1;
    errno = saved_errno;
    if (errno != EEXIST) break;
  }
  fail(path, std::string("cannot create a temporary file in its folder: ") + std::strerror(errno));
}

}  // namespace

AtomicFile::AtomicFile(const std::filesystem::path& target) : target_(target) {
  if (target_.filename().empty()) fail(target_, "is not a file name");
  // A link is written through: the file it points to is replaced, the link stays a link (renaming
  // over the link itself would silently turn it into a plain file).
  std::error_code ec;
  if (std::filesystem::is_symlink(std::filesystem::symlink_status(target_, ec))) {
    target_ = std::filesystem::canonical(target, ec);
    if (ec) fail(target, "is a symbolic link to a missing file or folder; not written");
  }
  file_ = open_temporary(target_, temporary_, slot_);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    if (file_ != nullptr) std::fclose(file_);
    std::error_code ignored;
    std::filesystem::remove(temporary_, ignored);
  }
  // Out of the table only once the file is gone: a signal before then still removes it.
  release_temporary(slot_);
}

void AtomicFile::commit() {
  finish();
  std::error_code ec;
  std::filesystem::rename(temporary_, target_, ec);
  if (ec) fail(target_, "cannot replace the file: " + ec.message());
  mark_committed();
}

void AtomicFile::finish() {
  if (file_ == nullptr) return;
  const bool write_failed = std::fflush(file_) != 0 || std::ferror(file_) != 0;
  const int saved_errno = errno;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (write_failed || close_failed) {
    fail(target_, std::string("write failed: ") + std::strerror(saved_errno));
  }
}

namespace {
thread_local AtomicFileGroup* current_group = nullptr;
}  // namespace

AtomicFileGroup::AtomicFileGroup() : previous_(current_group) { current_group = this; }

AtomicFileGroup::~AtomicFileGroup() { current_group = previous_; }

AtomicFileGroup* AtomicFileGroup::current() { return current_group; }

void AtomicFileGroup::adopt(std::unique_ptr<AtomicFile> file) { files_.push_back(std::move(file)); }

void AtomicFileGroup::commit() {
  current_group = previous_;  // nothing more joins the group
  std::error_code ec;
  // A folder in the way would be moved aside and replaced by a file, which a single write never
  // does (its rename fails): refuse before anything moves.
  for (const auto& file : files_) {
    if (std::filesystem::is_directory(std::filesystem::symlink_status(file->target(), ec))) {
      fail(file->target(), "cannot replace the file: it is a directory");
    }
  }
  // Phase 1: the existing targets move aside (same folder, so that the renames are atomic).
  std::vector<std::filesystem::path> backups(files_.size());
  const auto restore = [&](std::size_t placed) {
    for (std::size_t i = 0; i < files_.size(); ++i) {
      std::error_code ignored;
      if (i < placed && backups[i].empty()) std::filesystem::remove(files_[i]->target(), ignored);
      if (!backups[i].empty()) std::filesystem::rename(backups[i], files_[i]->target(), ignored);
    }
  };
  for (std::size_t i = 0; i < files_.size(); ++i) {
    const std::filesystem::path& target = files_[i]->target();
    if (!std::filesystem::exists(std::filesystem::symlink_status(target, ec))) continue;
    const std::filesystem::path backup = temporary_path_for(target);
    std::filesystem::rename(target, backup, ec);
    if (ec) {
      restore(0);
      fail(target, "cannot replace the file: " + ec.message());
    }
    backups[i] = backup;
  }
  // Phase 2: the new files move in.
  for (std::size_t i = 0; i < files_.size(); ++i) {
    std::filesystem::rename(files_[i]->temporary(), files_[i]->target(), ec);
    if (ec) {
      const std::string message = ec.message();
      restore(i);
      fail(files_[i]->target(), "cannot replace the file: " + message);
    }
    files_[i]->mark_committed();
  }
  for (const auto& backup : backups) {
    if (!backup.empty()) std::filesystem::remove(backup, ec);
  }
}

void AtomicFile::write(const char* data, std::size_t bytes) {
  if (std::fwrite(data, 1, bytes, file_) != bytes) {
    fail(target_, std::string("write failed: ") + std::strerror(errno));
  }
}

void OutputSink::flush() {
  if (buffer_.empty()) return;
  file_.write(buffer_.data(), buffer_.size());
  buffer_.clear();
}

void OutputSink::write(const char* data, std::size_t bytes) {
  flush();
  file_.write(data, bytes);
}

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(OutputSink&)>& body) {
  auto file = std::make_unique<AtomicFile>(path);
  OutputSink sink(*file);
  body(sink);
  sink.flush();
  if (AtomicFileGroup* group = AtomicFileGroup::current()) {
    file->finish();
    group->adopt(std::move(file));
  } else {
    file->commit();
  }
}

void write_lines(OutputSink& sink, std::int64_t count, int threads,
                 const std::function<void(std::string&, std::int64_t)>& append_line) {
  // Blocks of 2,048 items, a batch of 16 blocks at a time, each block into a text of its own.
  constexpr std::int64_t kBlock = 2048;
  constexpr std::int64_t kBlocksPerBatch = 16;
  std::vector<std::string> texts(static_cast<std::size_t>(kBlocksPerBatch));
  detail::ReportedPass pass(count);  // the batches are one pass of the progress display
  for (std::int64_t first = 0; first < count; first += kBlock * kBlocksPerBatch) {
    const std::int64_t n = std::min<std::int64_t>(kBlock * kBlocksPerBatch, count - first);
    detail::parallel_for_blocks(n, kBlock, threads, [&](std::int64_t begin, std::int64_t end) {
      // Formatted into a string object of this thread's own: the texts' objects share cache
      // lines, and a length updated there on every append would bounce them between threads.
      std::string text = std::move(texts[static_cast<std::size_t>(begin / kBlock)]);
      text.clear();
      for (auto i = begin; i < end; ++i) append_line(text, first + i);
      texts[static_cast<std::size_t>(begin / kBlock)] = std::move(text);
    });
    for (std::int64_t b = 0; b * kBlock < n; ++b) {
      const std::string& text = texts[static_cast<std::size_t>(b)];
      sink.write(text.data(), text.size());
    }
    pass.advance(first + n);
  }
  pass.finish();
}

}  // namespace io_detail

void write_text_file(const std::filesystem::path& path, std::string_view text) {
  io_detail::write_atomically(path, [&](io_detail::OutputSink& sink) {
    sink.buffer().append(text);
    sink.maybe_flush();
  });
}

}  // namespace focal
