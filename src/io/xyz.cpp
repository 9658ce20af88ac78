// Point-cloud text (.xyz, .xyzn, .xyzrgb, .pwn, .pts, .txt, .csv): one point per line, `x y z [nx
// ny nz]`, numbers separated by blanks or commas (or both), `#` starting a comment. Optional first
// lines:
//  - a header line with a token that is not a number ("x,y,z,nx,ny,nz", "X Y Z"): it must name
//    the columns x, y, z (and may name nx, ny, nz, or PCL's normal_x, normal_y, normal_z), which
//    are read, other columns skipped; a leading "//" (CloudCompare's "//X,Y,Z,R,G,B") is not part
//    of the first name; without a header the first three columns are the position and, in a
//    six-column file, the last three the normal;
//  - a single integer (the point count of Leica .pts files), which is skipped.
// Every data line has the column count of the first one. Columns beyond those read (intensity,
// colours) are skipped; a file of other than six columns without a header naming nx, ny, nz has
// no normals. Six columns without a header whose last three look like colours rather than
// normals (x y z r g b, as photogrammetry and CloudCompare write them) are an error asking for a
// header: read as normals they would turn half of the curvature signs without a word. Open3D's
// .xyzn (x y z nx ny nz) and .xyzrgb (x y z r g b, the colours skipped) say what six columns
// hold; such a file without a header must have six.

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/atomic_file.h"
#include "io/file_bytes.h"
#include "io/format_readers.h"
#include "io/number_text.h"
#include "io/text_scan.h"

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

/// Whether the three values of each point (3 per point) read as a headerless file's normals
/// look like colours instead: none negative (a surface's normals point to both sides of some
/// axis unless it faces one octant) and either one above 1 (integer colours) or fewer than half
/// of the nonzero rows of unit length within 10% (colours in [0, 1]; a plane's exact normals,
/// such as 0 0 1 everywhere, are unit and so stay normals, and zero rows, which some writers
/// give points without a normal, are neither).
bool look_like_colours(const std::vector<double>& values) {
  if (values.empty()) return false;
  if (std::any_of(values.begin(), values.end(), [](double v) { return !(v >= 0.0); })) {
    return false;
  }
  if (std::any_of(values.begin(), values.end(), [](double v) { return v > 1.0; })) return true;
  std::size_t unit = 0, nonzero = 0;
  for (std::size_t i = 0; i + 2 < values.size(); i += 3) {
    const double length = std::sqrt(values[i] * values[i] + values[i + 1] * values[i + 1] +
                                    values[i + 2] * values[i + 2]);
    if (length > 0.0) ++nonzero;
    if (std::abs(length - 1.0) <= 0.1) ++unit;
  }
  return 2 * unit < nonzero;
}

/// The columns a header names, when it names x, y and z.
std::optional<Columns> columns_named(const std::vector<std::string_view>& header) {
  const auto find = [&](std::string_view name) {
    for (std::size_t c = 0; c < header.size(); ++c) {
      std::string_view token = header[c];
      if (c == 0 && token.starts_with("//")) token.remove_prefix(2);
      if (io_detail::to_lower(token) == name) return static_cast<int>(c);
    }
    return -1;
  };
  Columns columns;
  columns.position = {find("x"), find("y"), find("z")};
  if (std::any_of(columns.position.begin(), columns.position.end(), [](int c) { return c < 0; })) {
    return std::nullopt;
  }
  const auto either = [&](std::string_view name, std::string_view pcl_name) {
    const int c = find(name);
    return c >= 0 ? c : find(pcl_name);
  };
  const std::array<int, 3> normal{either("nx", "normal_x"), either("ny", "normal_y"),
                                  either("nz", "normal_z")};
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

/// What a headerless six-column file holds: Open3D's extensions say (.xyzn normals, .xyzrgb
/// colours); other extensions read normals unless they look like colours.
enum class SixColumns { judged, normals, colours };

SixColumns six_columns_of(const std::filesystem::path& path) {
  const std::string ext = io_detail::to_lower(path.extension().string());
  if (ext == ".xyzn") return SixColumns::normals;
  if (ext == ".xyzrgb") return SixColumns::colours;
  return SixColumns::judged;
}

class XyzReader {
 public:
  XyzReader(const std::filesystem::path& path, std::string_view text)
      : path_(path), cursor_(text), six_(six_columns_of(path)) {}

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
    if (!named && width_ == 6 && six_ != SixColumns::colours) {
      columns_.normal = std::array<int, 3>{3, 4, 5};
    }
    if (!named && six_ != SixColumns::judged && width_ != 6) {
      fail_at_line(path_, cursor_.line_number(),
                   std::string("expected 6 numbers (") +
                       (six_ == SixColumns::normals ? "x y z nx ny nz" : "x y z r g b") +
                       ", as the extension says), found " + std::to_string(width_));
    }
    check_columns_exist();
    do read_point();
    while (next_line());
    if (!named && six_ == SixColumns::judged && columns_.normal && look_like_colours(normals_)) {
      fail(path_,
           "its columns 4-6 (read as normals in a six-column file without a header) look like "
           "colours, not normals (none negative; first row " +
               io_detail::quoted(first_normal()) +
               "); give the file a header line naming its columns ('x y z r g b' reads the "
               "positions alone, 'x y z nx ny nz' reads them as normals), or Open3D's extension "
               "(.xyzrgb or .xyzn)");
    }
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

  /// A header may name its columns in any order (nx after nz), so the last one read is the
  /// largest of all six, not the normal's third.
  /// The first row's three values read as a normal, for the colour error.
  [[nodiscard]] std::string first_normal() const {
    std::string text;
    for (int c = 0; c < 3; ++c) {
      if (c > 0) text += ' ';
      io_detail::append_number(text, normals_[static_cast<std::size_t>(c)]);
    }
    return text;
  }

  void check_columns_exist() {
    int last = *std::max_element(columns_.position.begin(), columns_.position.end());
    if (columns_.normal) {
      last = std::max(last, *std::max_element(columns_.normal->begin(), columns_.normal->end()));
    }
    if (width_ < 3 || static_cast<std::size_t>(last) >= width_) {
      fail_at_line(path_, cursor_.line_number(),
                   "expected at least " + std::to_string(std::max(last + 1, 3)) +
                       " numbers (x y z [nx ny nz]), found " + std::to_string(width_));
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
  SixColumns six_;
};

}  // namespace

namespace io_detail {

Mesh read_xyz(const std::filesystem::path& path) {
  const FileBytes text = read_whole_file(path);
  return parse_xyz(path, text.view());
}

Mesh parse_xyz(const std::filesystem::path& path, std::string_view data) {
  return XyzReader(path, data).read();
}

}  // namespace io_detail

void write_xyz(const std::filesystem::path& path, const Mesh& mesh, const WriteOptions& options) {
  // Read back, a .xyzrgb file's last three columns are colours: the normals would be lost.
  if (six_columns_of(path) == SixColumns::colours) {
    fail(path,
         "writing .xyzrgb is not supported (focal writes no colours; use .xyz, or .xyzn for "
         "x y z nx ny nz)");
  }
  validate_mesh_arrays(mesh.V, mesh.F, mesh.N, ("write_xyz: " + path.string()).c_str());
  const bool normals = mesh.has_normals();
  io_detail::write_atomically(path, [&](io_detail::OutputSink& sink) {
    io_detail::write_lines(sink, mesh.V.rows(), 0, [&](std::string& line, std::int64_t i) {
      io_detail::append_vertex_line(line, mesh, i, normals, options.precision);
    });
  });
}

}  // namespace focal
