// Point-cloud text (.xyz, .pts, .txt, .csv): one point per line, `x y z [nx ny nz]`, numbers
// separated by blanks or commas (or both), `#` starting a comment. Optional first lines:
//  - a header line with a token that is not a number ("x,y,z,nx,ny,nz", "X Y Z"): it must name
//    the columns x, y, z (and may name nx, ny, nz), which are read, other columns skipped;
//    without a header the first three columns are the position and, in a six-column file, the
//    last three the normal;
//  - a single integer (the point count of Leica .pts files), which is skipped.
// Every data line has the column count of the first one. Columns beyond those read (intensity,
// colours) are skipped; a file of other than six columns without a header naming nx, ny, nz has
// no normals.

#include <algorithm>
#include <array>
#include <optional>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/atomic_file.h"
#include "io/detail.h"

namespace focal {
namespace {

using io_detail::fail;
using io_detail::fail_at_line;

/// Blanks and commas both separate: "1,2,3", "1 2 3" and "1, 2, 3" read alike.
void split_fields(std::string_view line, std::string& scratch,
                  std::vector<std::string_view>& tokens) {
  scratch.assign(line);
  std::replace(scratch.begin(), scratch.end(), ',', ' ');
  io_detail::split_tokens(scratch, tokens);
}

/// Columns of x, y, z and (when present) nx, ny, nz.
struct Columns {
  std::array<int, 3> position{0, 1, 2};
  std::optional<std::array<int, 3>> normal;
};

/// The columns a header names, when it names x, y and z.
std::optional<Columns> columns_named(const std::vector<std::string_view>& header) {
  const auto find = [&](std::string_view name) {
    for (std::size_t c = 0; c < header.size(); ++c) {
      if (io_detail::to_lower(header[c]) == name) return static_cast<int>(c);
    }
    return -1;
  };
  Columns columns;
  columns.position = {find("x"), find("y"), find("z")};
  if (std::any_of(columns.position.begin(), columns.position.end(), [](int c) { return c < 0; })) {
    return std::nullopt;
  }
  const std::array<int, 3> normal{find("nx"), find("ny"), find("nz")};
  if (std::all_of(normal.begin(), normal.end(), [](int c) { return c >= 0; })) {
    columns.normal = normal;
  }
  return columns;
}

bool all_numbers(const std::vector<std::string_view>& tokens) {
  double value = 0.0;
  return std::all_of(tokens.begin(), tokens.end(),
                     [&](std::string_view t) { return io_detail::parse_double(t, value); });
}

class XyzReader {
 public:
  XyzReader(const std::filesystem::path& path, std::string_view text)
      : path_(path), cursor_(text) {}

  Mesh read() {
    if (!next_line()) fail(path_, "no points (expected lines of x y z [nx ny nz])");
    std::optional<Columns> named;
    if (!all_numbers(tokens_)) {
      // A header that names no x, y, z is not a point list (a table of other values, such as
      // focal's own curvature CSV): an error rather than numbers read as positions.
      named = columns_named(tokens_);
      if (!named) {
        fail_at_line(path_, cursor_.line_number(),
                     "the header names no x, y, z columns (a point cloud needs them, e.g. "
                     "'x,y,z,nx,ny,nz', or no header)");
      }
      if (!next_line()) fail(path_, "no points after the header line");
    }
    std::int64_t count = 0;
    if (tokens_.size() == 1 && io_detail::parse_int(tokens_[0], count)) {
      if (!next_line()) fail(path_, "no points after the point count");
    }
    width_ = tokens_.size();
    columns_ = named ? *named : Columns{};
    if (!named && width_ == 6) columns_.normal = std::array<int, 3>{3, 4, 5};
    check_columns_exist();
    do read_point();
    while (next_line());
    return finish();
  }

 private:
  bool next_line() {
    std::string_view line;
    while (cursor_.next(line)) {
      const std::size_t hash = line.find('#');
      if (hash != std::string_view::npos) line = line.substr(0, hash);
      split_fields(line, scratch_, tokens_);
      if (!tokens_.empty()) return true;
    }
    return false;
  }

  void check_columns_exist() {
    const int last = std::max(*std::max_element(columns_.position.begin(), columns_.position.end()),
                              columns_.normal ? (*columns_.normal)[2] : 0);
    if (width_ < 3 || static_cast<std::size_t>(last) >= width_) {
      fail_at_line(
          path_, cursor_.line_number(),
          "expected at least 3 numbers (x y z [nx ny nz]), found " + std::to_string(width_));
    }
  }

  double number(std::size_t column) {
    double value = 0.0;
    if (!io_detail::parse_double(tokens_[column], value)) {
      fail_at_line(path_, cursor_.line_number(),
                   "column " + std::to_string(column + 1) + ": " +
                       io_detail::quoted(tokens_[column]) + " is not a number");
    }
    return value;
  }

  void read_point() {
    if (tokens_.size() != width_) {
      fail_at_line(path_, cursor_.line_number(),
                   "expected " + std::to_string(width_) + " columns as on the first line, found " +
                       std::to_string(tokens_.size()));
    }
    for (const int c : columns_.position) positions_.push_back(number(static_cast<std::size_t>(c)));
    if (columns_.normal) {
      for (const int c : *columns_.normal) normals_.push_back(number(static_cast<std::size_t>(c)));
    }
  }

  Mesh finish() {
    const auto n = static_cast<Eigen::Index>(positions_.size() / 3);
    if (n > std::numeric_limits<std::int32_t>::max()) {
      fail(path_, "more points than 32-bit indices can address");
    }
    Mesh mesh;
    mesh.V = Eigen::Map<const RowMatrixX3d>(positions_.data(), n, 3);
    if (columns_.normal) mesh.N = Eigen::Map<const RowMatrixX3d>(normals_.data(), n, 3);
    mesh.F.resize(0, 3);
    return mesh;
  }

  const std::filesystem::path& path_;
  io_detail::LineCursor cursor_;
  std::string scratch_;
  std::vector<std::string_view> tokens_;
  std::size_t width_ = 0;
  Columns columns_;
  std::vector<double> positions_;
  std::vector<double> normals_;
};

}  // namespace

namespace io_detail {

Mesh read_xyz(const std::filesystem::path& path) {
  const FileBytes text = read_whole_file(path);
  return XyzReader(path, text.view()).read();
}

}  // namespace io_detail

void write_xyz(const std::filesystem::path& path, const Mesh& mesh, const WriteOptions& options) {
  if (options.threads < 0) throw InvalidInput("write_xyz: threads must be >= 0");
  validate_mesh_arrays(mesh.V, mesh.F, mesh.N, ("write_xyz: " + path.string()).c_str(),
                       options.threads);
  const bool normals = mesh.has_normals();
  io_detail::write_atomically(path, [&](io_detail::OutputSink& sink) {
    io_detail::write_lines(
        sink, mesh.V.rows(), options.threads, [&](std::string& line, std::int64_t i) {
          io_detail::append_vertex_line(line, mesh, i, normals, options.precision);
        });
  });
}

}  // namespace focal
