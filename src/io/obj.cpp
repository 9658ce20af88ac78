// Wavefront OBJ reading and writing (geometry only: v, vn and f; materials, texture coordinates,
// groups, lines and free-form geometry are not part of a triangle mesh and are ignored).

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/atomic_file.h"
#include "io/detail.h"

namespace focal {
namespace {

using io_detail::fail_at_line;

/// Offset of the first control byte other than blanks and line breaks, or npos.
std::size_t find_control_byte(std::string_view text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if ((byte < 0x20 && byte != '\t' && byte != '\n' && byte != '\r' && byte != '\v' &&
         byte != '\f') ||
        byte == 0x7F) {
      return i;
    }
  }
  return std::string_view::npos;
}

/// One face corner as written: vertex and normal indices, already resolved to 0-based
/// (relative indices applied), not yet range-checked. normal is -1 when the corner has none.
struct Corner {
  std::int64_t vertex;
  std::int64_t normal;
};

/// The statements of an OBJ text, or of a run of its lines, in file order.
struct ObjData {
  std::vector<double> positions;          // 3 per vertex
  std::vector<double> normals;            // 3 per vn
  std::size_t texture_count = 0;          // vt lines, for relative texture indices
  std::vector<Corner> corners;            // all face corners, polygon after polygon
  std::vector<std::size_t> polygon_end;   // one past each polygon's last corner
  std::vector<std::size_t> polygon_line;  // each polygon's line
  std::size_t lines = 0;                  // lines of the text read
};

/// What an ObjReader reads: a whole file, or a run of lines from inside one (read_obj_chunks).
enum class ObjText { whole_file, run_of_lines };

/// Thrown by a reader of a run of lines that meets a relative index: it refers to the elements
/// before the run, which only a reader of the whole file knows.
struct NeedsWholeFile {};

class ObjReader {
 public:
  ObjReader(const std::filesystem::path& path, ObjText scope) : path_(path), scope_(scope) {}

  ObjData read(std::string_view text) {
    io_detail::LineCursor cursor(text);
    std::string_view line;
    std::vector<std::string_view> tokens;
    while (cursor.next(line)) {
      line_ = cursor.line_number();
      io_detail::split_tokens(io_detail::strip_comment(line), tokens);
      if (tokens.empty()) continue;
      if (tokens[0] == "v") {
        read_triple(tokens, "coordinates", d_.positions);
      } else if (tokens[0] == "vn") {
        read_triple(tokens, "normal components", d_.normals);
      } else if (tokens[0] == "vt") {
        ++d_.texture_count;
      } else if (tokens[0] == "f") {
        read_face(tokens);
      }
    }
    d_.lines = cursor.line_number();
    return std::move(d_);
  }

 private:
  /// `v x y z [w] [r g b]` and `vn x y z`: the first three numbers are kept.
  void read_triple(const std::vector<std::string_view>& tokens, const char* what,
                   std::vector<double>& out) const {
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
    if (scope_ == ObjText::run_of_lines) throw NeedsWholeFile{};
    const std::int64_t resolved = static_cast<std::int64_t>(count) + index;
    if (resolved < 0) {
      fail_at_line(path_, line_,
                   "face " + std::to_string(d_.polygon_end.size()) + ": relative " + what +
                       " index " + std::to_string(index) + " reaches before the first " + what);
    }
    return resolved;
  }

  /// A corner is v, v/vt, v//vn or v/vt/vn.
  Corner parse_corner(std::string_view token) const {
    const std::size_t slash1 = token.find('/');
    Corner c{resolve(token.substr(0, slash1), d_.positions.size() / 3, "vertex"), -1};
    if (slash1 == std::string_view::npos) return c;
    const std::size_t slash2 = token.find('/', slash1 + 1);
    // Texture coordinates are not used, but a malformed one is still an error.
    const std::string_view texture = token.substr(slash1 + 1, slash2 - slash1 - 1);
    if (!texture.empty()) (void)resolve(texture, d_.texture_count, "texture coordinate");
    if (slash2 == std::string_view::npos) return c;
    const std::string_view normal = token.substr(slash2 + 1);
    if (!normal.empty()) c.normal = resolve(normal, d_.normals.size() / 3, "normal");
    return c;
  }

  void read_face(const std::vector<std::string_view>& tokens) {
    if (tokens.size() < 4) {
      fail_at_line(path_, line_,
                   "face " + std::to_string(d_.polygon_end.size()) + " has " +
                       std::to_string(tokens.size() - 1) + " vertices; a face needs at least 3");
    }
    for (std::size_t i = 1; i < tokens.size(); ++i) d_.corners.push_back(parse_corner(tokens[i]));
    d_.polygon_end.push_back(d_.corners.size());
    d_.polygon_line.push_back(line_);
  }

  const std::filesystem::path& path_;
  ObjText scope_;
  std::size_t line_ = 0;
  ObjData d_;
};

/// The runs of lines read one after the other, as one reader of their whole text would have
/// read them (no relative indices, so only the polygons' corner offsets and lines shift).
ObjData concatenate(std::vector<ObjData>& parts) {
  ObjData all;
  std::size_t positions = 0, normals = 0, corners = 0, polygons = 0;
  for (const ObjData& p : parts) {
    positions += p.positions.size();
    normals += p.normals.size();
    corners += p.corners.size();
    polygons += p.polygon_end.size();
  }
  all.positions.reserve(positions);
  all.normals.reserve(normals);
  all.corners.reserve(corners);
  all.polygon_end.reserve(polygons);
  all.polygon_line.reserve(polygons);
  for (ObjData& p : parts) {
    all.positions.insert(all.positions.end(), p.positions.begin(), p.positions.end());
    all.normals.insert(all.normals.end(), p.normals.begin(), p.normals.end());
    const std::size_t corner_offset = all.corners.size();
    all.corners.insert(all.corners.end(), p.corners.begin(), p.corners.end());
    for (const std::size_t end : p.polygon_end) all.polygon_end.push_back(corner_offset + end);
    for (const std::size_t line : p.polygon_line) all.polygon_line.push_back(all.lines + line);
    all.texture_count += p.texture_count;
    all.lines += p.lines;
    p = {};  // free each part once copied: the peak stays near one copy of the data
  }
  return all;
}

/// Builds the mesh from the statements of a whole file.
class ObjMeshBuilder {
 public:
  ObjMeshBuilder(const std::filesystem::path& path, const ObjData& d) : path_(path), d_(d) {}

  Mesh build() const {
    check_ranges();
    Mesh mesh;
    const auto vertex_count = static_cast<Eigen::Index>(d_.positions.size() / 3);
    if (vertex_count > std::numeric_limits<std::int32_t>::max()) {
      io_detail::fail(path_, "more vertices than 32-bit indices can address");
    }
    mesh.V = Eigen::Map<const RowMatrixX3d>(d_.positions.data(), vertex_count, 3);
    const bool any_normal = std::any_of(d_.corners.begin(), d_.corners.end(),
                                        [](const Corner& c) { return c.normal >= 0; });
    if (any_normal) {
      mesh.N = vertex_normals(vertex_count);
    } else if (d_.polygon_end.empty() && vertex_count > 0 &&
               d_.normals.size() == d_.positions.size()) {
      // A point cloud (no faces) with one `vn` per `v`, as write_obj writes one: paired in order.
      mesh.N = Eigen::Map<const RowMatrixX3d>(d_.normals.data(), vertex_count, 3);
    }

    io_detail::TriangleCollector triangles;
    triangles.reserve(d_.polygon_end.size());
    std::vector<std::int32_t> polygon;
    std::size_t begin = 0;
    for (std::size_t p = 0; p < d_.polygon_end.size(); ++p) {
      polygon.clear();
      for (std::size_t k = begin; k < d_.polygon_end[p]; ++k) {
        polygon.push_back(static_cast<std::int32_t>(d_.corners[k].vertex));
      }
      triangles.add_polygon(polygon.data(), polygon.size(), static_cast<std::int32_t>(p));
      begin = d_.polygon_end[p];
    }
    triangles.move_into(mesh);
    return mesh;
  }

 private:
  /// Indices may refer forward, so the range check waits until every v and vn is known.
  void check_ranges() const {
    const auto vertices = static_cast<std::int64_t>(d_.positions.size() / 3);
    const auto normals = static_cast<std::int64_t>(d_.normals.size() / 3);
    std::size_t begin = 0;
    for (std::size_t p = 0; p < d_.polygon_end.size(); ++p) {
      for (std::size_t k = begin; k < d_.polygon_end[p]; ++k) {
        const Corner& c = d_.corners[k];
        if (c.vertex >= vertices) {
          fail_at_line(path_, d_.polygon_line[p],
                       "face " + std::to_string(p) + " refers to vertex " +
                           std::to_string(c.vertex + 1) + " but there are " +
                           std::to_string(vertices) + " vertices");
        }
        if (c.normal >= normals) {
          fail_at_line(path_, d_.polygon_line[p],
                       "face " + std::to_string(p) + " refers to normal " +
                           std::to_string(c.normal + 1) + " but there are " +
                           std::to_string(normals) + " normals");
        }
      }
      begin = d_.polygon_end[p];
    }
  }
  /// Per vertex: the referenced normal, or the normalised average of the distinct normals
  /// (by vn index) referenced for it; NaN where a vertex is never referenced with a normal.
  RowMatrixX3d vertex_normals(Eigen::Index vertex_count) const {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    RowMatrixX3d N = RowMatrixX3d::Constant(vertex_count, 3, kNaN);
    std::vector<std::int64_t> first(static_cast<std::size_t>(vertex_count), -1);
    std::vector<std::pair<std::int64_t, std::int64_t>> others;  // (vertex, normal) conflicts
    for (const Corner& c : d_.corners) {
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
    return {d_.normals[k], d_.normals[k + 1], d_.normals[k + 2]};
  }

  const std::filesystem::path& path_;
  const ObjData& d_;
};

/// The control-byte check and the statements of a whole file, read in file order: the
/// reference that the chunked read must equal, and the one that reports errors.
ObjData read_obj_serially(const std::filesystem::path& path, std::string_view data) {
  const std::size_t control = find_control_byte(data);
  if (control != std::string_view::npos) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned char>(data[control]));
    io_detail::fail_at_offset(path, control,
                              std::string("control byte ") + hex + ": binary data, not OBJ text");
  }
  return ObjReader(path, ObjText::whole_file).read(data);
}

/// The statements of a whole file read as runs of lines in parallel, or nothing when the file is
/// too small to split or a run meets anything a run cannot judge alone (an error, whose message
/// needs the face count and line so far, or a relative index): the serial read then gives the
/// exact result or error. Runs without either are read exactly as the serial reader reads them,
/// so the concatenation is its result bit for bit, whatever the thread count.
std::optional<ObjData> read_obj_chunks(const std::filesystem::path& path, std::string_view data,
                                       int threads, std::size_t chunk_bytes) {
  const std::vector<std::size_t> cuts = io_detail::line_aligned_cuts(data, chunk_bytes);
  const auto chunks = static_cast<std::int64_t>(cuts.size()) - 1;
  if (chunks < 2 || detail::thread_count(threads) < 2) return std::nullopt;
  std::vector<ObjData> parts(static_cast<std::size_t>(chunks));
  std::atomic<bool> serial{false};
  detail::parallel_chunks(chunks, threads, [&](std::int64_t c) {
    if (serial.load(std::memory_order_relaxed)) return;
    const auto k = static_cast<std::size_t>(c);
    const std::string_view text = data.substr(cuts[k], cuts[k + 1] - cuts[k]);
    try {
      if (find_control_byte(text) != std::string_view::npos) throw NeedsWholeFile{};
      parts[k] = ObjReader(path, ObjText::run_of_lines).read(text);
    } catch (const IoError&) {
      serial.store(true, std::memory_order_relaxed);
    } catch (const NeedsWholeFile&) {
      serial.store(true, std::memory_order_relaxed);
    }
  });
  if (serial.load()) return std::nullopt;
  return concatenate(parts);
}

/// `data` less a UTF-8 byte order mark, after the checks of its start.
std::string_view obj_text(const std::filesystem::path& path, std::string_view data) {
  // OBJ has no header, so a 0-byte file would read as a valid empty mesh; it is nearly always a
  // failed export or copy, so it is reported like the empty files of the other formats.
  if (data.empty()) io_detail::fail(path, "empty file (0 bytes), expected OBJ data");
  // A UTF-8 byte order mark (editors on Windows add one) would turn the first keyword into an
  // unknown one, silently dropping the first vertex and shifting every index.
  constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
  if (data.starts_with(kByteOrderMark)) data.remove_prefix(kByteOrderMark.size());
  // OBJ ignores statements it does not know, so without these checks any file (an image, a
  // binary, a PLY renamed .obj) would read as an empty mesh. OBJ is text: control bytes other
  // than blanks and line breaks (NUL in UTF-16 and binary data, for a start) mean it is not OBJ
  // (read_obj_serially).
  if (data.starts_with("\xFF\xFE") || data.starts_with("\xFE\xFF")) {
    io_detail::fail(path, "starts with a UTF-16 byte order mark; OBJ files are ASCII/UTF-8 text");
  }
  return data;
}

Mesh obj_mesh(const std::filesystem::path& path, const ObjData& statements) {
  Mesh mesh = ObjMeshBuilder(path, statements).build();
  if (mesh.V.rows() == 0) io_detail::fail(path, "no vertices ('v' lines): not an OBJ mesh");
  return mesh;
}

}  // namespace

namespace io_detail {

Mesh parse_obj(const std::filesystem::path& path, std::string_view data) {
  return parse_obj(path, data, 0, kTextChunkBytes);
}

std::optional<Mesh> parse_obj_in_chunks(const std::filesystem::path& path, std::string_view data,
                                        int threads, std::size_t chunk_bytes) {
  const std::string_view text = obj_text(path, data);
  std::optional<ObjData> statements = read_obj_chunks(path, text, threads, chunk_bytes);
  if (!statements) return std::nullopt;
  return obj_mesh(path, *statements);
}

Mesh parse_obj(const std::filesystem::path& path, std::string_view data, int threads,
               std::size_t chunk_bytes) {
  if (std::optional<Mesh> mesh = parse_obj_in_chunks(path, data, threads, chunk_bytes)) {
    return std::move(*mesh);
  }
  return obj_mesh(path, read_obj_serially(path, obj_text(path, data)));
}

Mesh read_obj(const std::filesystem::path& path, int threads) {
  return parse_obj(path, read_whole_file(path), threads, kTextChunkBytes);
}

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
