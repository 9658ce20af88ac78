#include "focal/io/mesh_io.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <system_error>

#include "focal/core/error.h"
#include "io/detail.h"

namespace focal {
namespace io_detail {

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

std::string read_whole_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) fail(path, "no such file");
  if (std::filesystem::is_directory(status)) fail(path, "is a directory, not a mesh file");

  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) fail(path, std::string("cannot open for reading: ") + std::strerror(errno));
  // Read into a buffer one byte larger than the reported size, so that a file that grew (or a
  // size query that is wrong, as for pipes) is noticed and the buffer extended.
  std::string data;
  const auto size_hint = std::filesystem::file_size(path, ec);
  data.resize(ec ? std::size_t{1} << 20 : static_cast<std::size_t>(size_hint) + 1);
  std::size_t used = 0;
  for (;;) {
    used += std::fread(data.data() + used, 1, data.size() - used, file);
    if (used < data.size()) break;
    data.resize(2 * data.size());
  }
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) fail(path, "read error");
  data.resize(used);
  return data;
}

void check_count_fits(const std::filesystem::path& path, std::string_view where,
                      std::uint64_t count, std::uint64_t min_bytes, std::uint64_t available,
                      std::string_view what) {
  // The last element of a text file may lack its separator, hence the +1.
  if (min_bytes > 0 && count > (available + 1) / min_bytes) {
    fail(path, std::string(where) + ": header declares " + std::to_string(count) + " " +
                   std::string(what) + " but the " + std::to_string(available) +
                   " bytes that follow can hold at most " +
                   std::to_string((available + 1) / min_bytes));
  }
  if (count > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
    fail(path, std::string(where) + ": header declares " + std::to_string(count) + " " +
                   std::string(what) + ", more than 32-bit indices can address");
  }
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

bool LineCursor::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  const std::size_t end = text_.find('\n', pos_);
  const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
  line = text_.substr(pos_, stop - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = end == std::string_view::npos ? text_.size() : end + 1;
  ++next_line_;
  return true;
}

namespace {
bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
}  // namespace

void split_tokens(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    while (i < n && is_blank(line[i])) ++i;
    const std::size_t start = i;
    while (i < n && !is_blank(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}

bool parse_double(std::string_view token, double& value) {
  // from_chars rejects '+' but writers emit it ("+1.5e+00").
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  // Out-of-range values (1e999) come back as errc::result_out_of_range: not a number we can keep.
  return ec == std::errc() && ptr == end && !token.empty();
}

bool parse_int(std::string_view token, std::int64_t& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end && !token.empty();
}

void TriangleCollector::reserve(std::size_t polygons) {
  corners_.reserve(3 * polygons);
  source_.reserve(polygons);
}

void TriangleCollector::add_polygon(const std::int32_t* corners, std::size_t count,
                                    std::int32_t polygon) {
  for (std::size_t k = 1; k + 1 < count; ++k) {
    corners_.push_back(corners[0]);
    corners_.push_back(corners[k]);
    corners_.push_back(corners[k + 1]);
    source_.push_back(polygon);
  }
}

void TriangleCollector::move_into(Mesh& mesh) {
  const auto triangles = static_cast<Eigen::Index>(source_.size());
  mesh.F = Eigen::Map<const RowMatrixX3i>(corners_.data(), triangles, 3);
  mesh.face_source = Eigen::Map<const Eigen::VectorXi>(source_.data(), triangles);
  corners_ = {};
  source_ = {};
}

namespace {
template <class T>
void append_floating(std::string& out, T value) {
  if (std::isnan(value)) {
    out += "nan";  // never "-nan": readers and spreadsheets agree on "nan"
    return;
  }
  if (std::isinf(value)) {
    out += value > 0 ? "inf" : "-inf";
    return;
  }
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, result.ptr);
}
}  // namespace

void append_number(std::string& out, double value) { append_floating(out, value); }
void append_number(std::string& out, float value) { append_floating(out, value); }

void append_number(std::string& out, std::int64_t value) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, result.ptr);
}

void OutputSink::flush() {
  if (buffer_.empty()) return;
  if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    fail(target_, std::string("write failed: ") + std::strerror(errno));
  }
  buffer_.clear();
}

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
std::FILE* open_temporary(const std::filesystem::path& path, std::filesystem::path& temp) {
  for (int attempt = 0; attempt < 16; ++attempt) {
    temp = temporary_path_for(path);
    std::FILE* file = std::fopen(temp.c_str(), "wbx");
    if (file != nullptr) return file;
    if (errno != EEXIST) break;
  }
  fail(path, std::string("cannot create a temporary file in its folder: ") + std::strerror(errno));
}

}  // namespace

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(OutputSink&)>& body) {
  if (path.filename().empty()) fail(path, "is not a file name");
  std::filesystem::path temp;
  std::FILE* file = open_temporary(path, temp);
  try {
    OutputSink sink(file, path);
    body(sink);
    sink.flush();
    const bool write_failed = std::fflush(file) != 0 || std::ferror(file) != 0;
    const int saved_errno = errno;
    const bool close_failed = std::fclose(file) != 0;
    file = nullptr;
    if (write_failed || close_failed) {
      fail(path, std::string("write failed: ") + std::strerror(saved_errno));
    }
    std::error_code ec;
    std::filesystem::rename(temp, path, ec);
    if (ec) fail(path, "cannot replace the file: " + ec.message());
  } catch (...) {
    if (file != nullptr) std::fclose(file);
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    throw;
  }
}

}  // namespace io_detail

MeshFormat mesh_format_from_path(const std::filesystem::path& path) {
  const std::string ext = io_detail::to_lower(path.extension().string());
  if (ext == ".obj") return MeshFormat::obj;
  if (ext == ".ply") return MeshFormat::ply;
  if (ext == ".off") return MeshFormat::off;
  if (ext == ".stl") return MeshFormat::stl;
  io_detail::fail(path, "unknown mesh format '" + path.extension().string() +
                            "' (expected .obj, .ply, .off or .stl)");
}

Mesh read_mesh(const std::filesystem::path& path, const ReadOptions& options) {
  if (options.threads < 0) throw InvalidInput("read_mesh: threads must be >= 0");
  switch (mesh_format_from_path(path)) {
    case MeshFormat::obj:
      return io_detail::read_obj(path);
    case MeshFormat::ply:
      return io_detail::read_ply(path, options.threads);
    case MeshFormat::off:
      return io_detail::read_off(path);
    case MeshFormat::stl:
      return io_detail::read_stl(path);
  }
  io_detail::fail(path, "unknown mesh format");
}

void write_mesh(const std::filesystem::path& path, const Mesh& mesh) {
  switch (mesh_format_from_path(path)) {
    case MeshFormat::ply:
      write_ply(path, mesh);
      return;
    case MeshFormat::obj:
      write_obj(path, mesh);
      return;
    case MeshFormat::off:
      write_off(path, mesh);
      return;
    case MeshFormat::stl:
      break;
  }
  // STL cannot hold shared vertices, so writing it would lose the vertex order the library
  // promises; the formats above keep it.
  io_detail::fail(path, "writing STL is not supported (use .ply, .obj or .off)");
}

}  // namespace focal
