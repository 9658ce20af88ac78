// Wavefront OBJ reading and writing (geometry only: v, vn and f; materials, texture coordinates,
// groups, lines and free-form geometry are not part of a triangle mesh and are ignored).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/atomic_file.h"
#include "io/detail.h"

namespace focal {
namespace {

using io_detail::fail_at_line;

/// One face corner as written: vertex and normal indices, already resolved to 0-based
/// (relative indices applied), not yet range-checked. normal is -1 when the corner has none.
struct Corner {
  std::int64_t vertex;
  std::int64_t normal;
};

class ObjReader {
 public:
  explicit ObjReader(const std::filesystem::path& path) : path_(path) {}

  Mesh read(std::string_view text) {
    io_detail::LineCursor cursor(text);
    std::string_view line;
    std::vector<std::string_view> tokens;
    while (cursor.next(line)) {
      line_ = cursor.line_number();
      io_detail::split_tokens(io_detail::strip_comment(line), tokens);
      if (tokens.empty()) continue;
      if (tokens[0] == "v") {
        read_triple(tokens, "coordinates", positions_);
      } else if (tokens[0] == "vn") {
        read_triple(tokens, "normal components", normals_);
      } else if (tokens[0] == "vt") {
        ++texture_count_;
      } else if (tokens[0] == "f") {
        read_face(tokens);
      }
    }
    return finish();
  }

 private:
  /// `v x y z [w] [r g b]` and `vn x y z`: the first three numbers are kept.
  void read_triple(const std::vector<std::string_view>& tokens, const char* what,
                   std::vector<double>& out) {
    if (tokens.size() < 4) {
      fail_at_line(
          path_, line_,
          "expected 3 " + std::string(what) + ", got " + std::to_string(tokens.size() - 1));
    }
    for (std::size_t i = 1; i < tokens.size(); ++i) {
      double value = 0.0;
      if (!io_detail::parse_double(tokens[i], value)) {
        fail_at_line(path_, line_, io_detail::quoted(tokens[i]) + " is not a number");
      }
      if (i <= 3) out.push_back(value);
    }
  }

  /// 1-based or negative (relative to the `count` elements read so far) to 0-based.
  std::int64_t resolve(std::string_view token, std::size_t count, const char* what) const {
    std::int64_t index = 0;
    if (!io_detail::parse_int(token, index) || index == 0) {
      fail_at_line(path_, line_, io_detail::quoted(token) + " is not a valid " + what + " index");
    }
    if (index > 0) return index - 1;
    const std::int64_t resolved = static_cast<std::int64_t>(count) + index;
    if (resolved < 0) {
      fail_at_line(path_, line_,
                   "face " + std::to_string(polygons_) + ": relative " + what + " index " +
                       std::to_string(index) + " reaches before the first " + what);
    }
    return resolved;
  }

  /// A corner is v, v/vt, v//vn or v/vt/vn.
  Corner parse_corner(std::string_view token) const {
    const std::size_t slash1 = token.find('/');
    Corner c{resolve(token.substr(0, slash1), positions_.size() / 3, "vertex"), -1};
    if (slash1 == std::string_view::npos) return c;
    const std::size_t slash2 = token.find('/', slash1 + 1);
    // Texture coordinates are not used, but a malformed one is still an error.
    const std::string_view texture = token.substr(slash1 + 1, slash2 - slash1 - 1);
    if (!texture.empty()) (void)resolve(texture, texture_count_, "texture coordinate");
    if (slash2 == std::string_view::npos) return c;
    const std::string_view normal = token.substr(slash2 + 1);
    if (!normal.empty()) c.normal = resolve(normal, normals_.size() / 3, "normal");
    return c;
  }

  void read_face(const std::vector<std::string_view>& tokens) {
    if (tokens.size() < 4) {
      fail_at_line(path_, line_,
                   "face " + std::to_string(polygons_) + " has " +
                       std::to_string(tokens.size() - 1) + " vertices; a face needs at least 3");
    }
    for (std::size_t i = 1; i < tokens.size(); ++i) corners_.push_back(parse_corner(tokens[i]));
    polygon_end_.push_back(corners_.size());
    polygon_line_.push_back(line_);
    ++polygons_;
  }

  /// Indices may refer forward, so the range check waits until every v and vn is known.
  void check_ranges() const {
    const auto vertices = static_cast<std::int64_t>(positions_.size() / 3);
    const auto normals = static_cast<std::int64_t>(normals_.size() / 3);
    std::size_t begin = 0;
    for (std::size_t p = 0; p < polygon_end_.size(); ++p) {
      for (std::size_t k = begin; k < polygon_end_[p]; ++k) {
        const Corner& c = corners_[k];
        if (c.vertex >= vertices) {
          fail_at_line(path_, polygon_line_[p],
                       "face " + std::to_string(p) + " refers to vertex " +
                           std::to_string(c.vertex + 1) + " but there are " +
                           std::to_string(vertices) + " vertices");
        }
        if (c.normal >= normals) {
          fail_at_line(path_, polygon_line_[p],
                       "face " + std::to_string(p) + " refers to normal " +
                           std::to_string(c.normal + 1) + " but there are " +
                           std::to_string(normals) + " normals");
        }
      }
      begin = polygon_end_[p];
    }
  }

  /// Per vertex: the referenced normal, or the normalised average of the distinct normals
  /// (by vn index) referenced for it; NaN where a vertex is never referenced with a normal.
  RowMatrixX3d vertex_normals(Eigen::Index vertex_count) const {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    RowMatrixX3d N = RowMatrixX3d::Constant(vertex_count, 3, kNaN);
    std::vector<std::int64_t> first(static_cast<std::size_t>(vertex_count), -1);
    std::vector<std::pair<std::int64_t, std::int64_t>> others;  // (vertex, normal) conflicts
    for (const Corner& c : corners_) {
      if (c.normal < 0) continue;
      auto& f = first[static_cast<std::size_t>(c.vertex)];
      if (f < 0) {
        f = c.normal;
      } else if (f != c.normal) {
        others.emplace_back(c.vertex, c.normal);
      }
    }
    for (Eigen::Index v = 0; v < vertex_count; ++v) {
      const auto f = first[static_cast<std::size_t>(v)];
      if (f >= 0) N.row(v) = normal(f);
    }
    std::sort(others.begin(), others.end());
    others.erase(std::unique(others.begin(), others.end()), others.end());
    for (const auto& [v, n] : others) N.row(v) += normal(n);
    for (std::size_t i = 0; i < others.size(); ++i) {
      if (i + 1 < others.size() && others[i + 1].first == others[i].first) continue;
      const auto v = others[i].first;
      const double length = N.row(v).norm();
      // Opposite normals cancel: no direction exists, so NaN rather than a made-up one.
      N.row(v) =
          length > 0 ? Eigen::RowVector3d(N.row(v) / length) : Eigen::RowVector3d::Constant(kNaN);
    }
    return N;
  }

  [[nodiscard]] Eigen::RowVector3d normal(std::int64_t n) const {
    const auto k = static_cast<std::size_t>(3 * n);
    return {normals_[k], normals_[k + 1], normals_[k + 2]};
  }

  Mesh finish() {
    check_ranges();
    Mesh mesh;
    const auto vertex_count = static_cast<Eigen::Index>(positions_.size() / 3);
    if (vertex_count > std::numeric_limits<std::int32_t>::max()) {
      io_detail::fail(path_, "more vertices than 32-bit indices can address");
    }
    mesh.V = Eigen::Map<const RowMatrixX3d>(positions_.data(), vertex_count, 3);
    const bool any_normal = std::any_of(corners_.begin(), corners_.end(),
                                        [](const Corner& c) { return c.normal >= 0; });
    if (any_normal) {
      mesh.N = vertex_normals(vertex_count);
    } else if (polygon_end_.empty() && vertex_count > 0 && normals_.size() == positions_.size()) {
      // A point cloud (no faces) with one `vn` per `v`, as write_obj writes one: paired in order.
      mesh.N = Eigen::Map<const RowMatrixX3d>(normals_.data(), vertex_count, 3);
    }

    io_detail::TriangleCollector triangles;
    triangles.reserve(polygon_end_.size());
    std::vector<std::int32_t> polygon;
    std::size_t begin = 0;
    for (std::size_t p = 0; p < polygon_end_.size(); ++p) {
      polygon.clear();
      for (std::size_t k = begin; k < polygon_end_[p]; ++k) {
        polygon.push_back(static_cast<std::int32_t>(corners_[k].vertex));
      }
      triangles.add_polygon(polygon.data(), polygon.size(), static_cast<std::int32_t>(p));
      begin = polygon_end_[p];
    }
    triangles.move_into(mesh);
    return mesh;
  }

  const std::filesystem::path& path_;
  std::size_t line_ = 0;
  std::vector<double> positions_;  // 3 per vertex
  std::vector<double> normals_;    // 3 per vn
  std::size_t texture_count_ = 0;  // vt lines so far, for relative texture indices
  std::vector<Corner> corners_;    // all face corners, polygon after polygon
  std::vector<std::size_t> polygon_end_;
  std::vector<std::size_t> polygon_line_;
  std::int64_t polygons_ = 0;
};

}  // namespace

namespace io_detail {

Mesh parse_obj(const std::filesystem::path& path, std::string_view data) {
  // OBJ has no header, so a 0-byte file would read as a valid empty mesh; it is nearly always a
  // failed export or copy, so it is reported like the empty files of the other formats.
  if (data.empty()) fail(path, "empty file (0 bytes), expected OBJ data");
  // A UTF-8 byte order mark (editors on Windows add one) would turn the first keyword into an
  // unknown one, silently dropping the first vertex and shifting every index.
  constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
  if (data.starts_with(kByteOrderMark)) data.remove_prefix(kByteOrderMark.size());
  // OBJ ignores statements it does not know, so without these checks any file (an image, a
  // binary, a PLY renamed .obj) would read as an empty mesh. OBJ is text: control bytes other
  // than blanks and line breaks (NUL in UTF-16 and binary data, for a start) mean it is not OBJ.
  if (data.starts_with("\xFF\xFE") || data.starts_with("\xFE\xFF")) {
    fail(path, "starts with a UTF-16 byte order mark; OBJ files are ASCII/UTF-8 text");
  }
  for (std::size_t i = 0; i < data.size(); ++i) {
    const auto byte = static_cast<unsigned char>(data[i]);
    if ((byte < 0x20 && byte != '\t' && byte != '\n' && byte != '\r' && byte != '\v' &&
         byte != '\f') ||
        byte == 0x7F) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02X", byte);
      io_detail::fail_at_offset(path, i,
                                std::string("control byte ") + hex + ": binary data, not OBJ text");
    }
  }
  Mesh mesh = ObjReader(path).read(data);
  if (mesh.V.rows() == 0) fail(path, "no vertices ('v' lines): not an OBJ mesh");
  return mesh;
}

Mesh read_obj(const std::filesystem::path& path) { return parse_obj(path, read_whole_file(path)); }

}  // namespace io_detail

void write_obj(const std::filesystem::path& path, const Mesh& mesh) {
  validate_mesh_arrays(mesh.V, mesh.F, mesh.N, ("write_obj: " + path.string()).c_str());
  const bool normals = mesh.has_normals();
  io_detail::write_atomically(path, [&](io_detail::OutputSink& sink) {
    std::string& out = sink.buffer();
    // `v x y z` lines, then `vn x y z` lines.
    const auto append_rows = [&](std::string_view keyword, const RowMatrixX3d& rows) {
      for (Eigen::Index i = 0; i < rows.rows(); ++i) {
        out += keyword;
        for (int c = 0; c < 3; ++c) {
          out += ' ';
          io_detail::append_number(out, rows(i, c));
        }
        out += '\n';
        sink.maybe_flush();
      }
    };
    append_rows("v", mesh.V);
    if (normals) append_rows("vn", mesh.N);
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
      out += 'f';
      for (int c = 0; c < 3; ++c) {
        const auto index = static_cast<std::int64_t>(mesh.F(f, c)) + 1;
        out += ' ';
        io_detail::append_number(out, index);
        if (normals) {
          out += "//";
          io_detail::append_number(out, index);
        }
      }
      out += '\n';
      sink.maybe_flush();
    }
  });
}

}  // namespace focal
