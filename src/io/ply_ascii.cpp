// The ascii body of a PLY file: one element per line, read in parallel runs of lines when it
// is large, else serially (the exact error of a malformed file).

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "io/file_bytes.h"
#include "io/ply.h"
#include "io/ply_read.h"
#include "io/text_scan.h"

namespace focal::io_detail::ply {
namespace {

class AsciiBody {
 public:
  AsciiBody(const std::filesystem::path& path, std::string_view body, std::size_t first_line)
      : path_(path), cursor_(body, first_line), size_(body.size()) {}

  void check_fits(const PlyElement& e) const {
    // Each element takes at least one non-blank line ("x\n"). A loose bound on purpose: it only
    // has to stop a header claiming 1e12 vertices before allocation; a merely malformed file
    // gets the precise message of the line where it goes wrong.
    if (e.properties.empty()) return;
    io_detail::check_count_fits(path_, "line " + std::to_string(cursor_.line_number() + 1), e.count,
                                2, size_ - cursor_.offset(), e.name + " elements");
  }

  void read_vertices(const PlyElement& e, const std::vector<int>& roles, double* V, double* N) {
    for (std::uint64_t i = 0; i < e.count; ++i) {
      next_element(e, i);
      read_vertex(e, roles, i, V, N);
    }
  }

  void read_faces(const PlyElement& e, std::size_t list_prop, std::int64_t vertex_count,
                  FaceLists kind, io_detail::TriangleCollector& triangles) {
    std::vector<std::int32_t> corners;
    for (std::uint64_t f = 0; f < e.count; ++f) {
      next_element(e, f);
      read_face(e, list_prop, vertex_count, kind, f, corners, triangles);
    }
  }

  void skip_element(const PlyElement& e) {
    if (e.properties.empty()) return;  // such elements occupy no text at all
    for (std::uint64_t i = 0; i < e.count; ++i) {
      next_element(e, i);
      check_element(e, i);
    }
  }

  /// After the last element: only blank lines may follow (more lines are a wrong count, or two
  /// files in one; never silently dropped). \throw IoError naming the first such line.
  void check_end(const PlyHeader& header) {
    if (!next_line()) return;
    std::string declared;
    for (const PlyElement& e : header.elements) {
      if (e.properties.empty()) continue;  // no text
      declared += (declared.empty() ? "" : ", ") + std::to_string(e.count) + " " + e.name;
    }
    fail_at_line(path_, cursor_.line_number(),
                 "data after the last element the header declares (" + declared + "): '" +
                     std::string(tokens_[0]) + "'");
  }

  /// Next line with tokens; false at the end of the text.
  bool next_line() {
    std::string_view line;
    while (cursor_.next(line)) {
      io_detail::split_tokens(line, tokens_);
      if (!tokens_.empty()) return true;
    }
    return false;
  }

  /// Vertex i from the current line into V (and N) by the properties' roles.
  void read_vertex(const PlyElement& e, const std::vector<int>& roles, std::uint64_t i, double* V,
                   double* N) const {
    std::size_t t = 0;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const auto& prop = e.properties[k];
      if (prop.is_list) {
        t += 1 + list_length(prop, e, i, t);
        continue;
      }
      need(t + 1, e, i);
      const int role = roles[k];
      if (role >= 0) {
        double value = 0.0;
        if (!io_detail::parse_double(tokens_[t], value)) not_a_number(e, i, tokens_[t]);
        if (role < 3) {
          V[3 * i + role] = value;
        } else {
          N[3 * i + role - 3] = value;
        }
      }
      ++t;
    }
    finish_element(t, e, i);
  }

  /// Face list f from the current line into `triangles` (`corners`: scratch).
  void read_face(const PlyElement& e, std::size_t list_prop, std::int64_t vertex_count,
                 FaceLists kind, std::uint64_t f, std::vector<std::int32_t>& corners,
                 io_detail::TriangleCollector& triangles) const {
    std::size_t t = 0;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const auto& prop = e.properties[k];
      if (!prop.is_list) {
        need(++t, e, f);
        continue;
      }
      const std::size_t n = list_length(prop, e, f, t);
      if (k == list_prop) read_polygon(e, t + 1, n, f, vertex_count, kind, corners, triangles);
      t += 1 + n;
    }
    finish_element(t, e, f);
  }

  /// Element i of a skipped element from the current line: only its token count is checked.
  void check_element(const PlyElement& e, std::uint64_t i) const {
    std::size_t t = 0;
    for (const auto& prop : e.properties) {
      t += prop.is_list ? 1 + list_length(prop, e, i, t) : 1;
      need(t, e, i);
    }
    finish_element(t, e, i);
  }

 private:
  void next_element(const PlyElement& e, std::uint64_t index) {
    if (!next_line()) {
      fail_at_line(path_, cursor_.line_number(),
                   "file ends inside " + e.name + " " + std::to_string(index) + " of " +
                       std::to_string(e.count));
    }
  }

  [[noreturn]] void wrong_count(const PlyElement& e, std::uint64_t index,
                                std::size_t expected) const {
    fail_at_line(path_, cursor_.line_number(),
                 e.name + " " + std::to_string(index) + ": expected " + std::to_string(expected) +
                     " values, got " + std::to_string(tokens_.size()));
  }

  void need(std::size_t tokens, const PlyElement& e, std::uint64_t index) const {
    if (tokens > tokens_.size()) wrong_count(e, index, tokens);
  }

  void finish_element(std::size_t used, const PlyElement& e, std::uint64_t index) const {
    if (used != tokens_.size()) wrong_count(e, index, used);
  }

  [[noreturn]] void not_a_number(const PlyElement& e, std::uint64_t index,
                                 std::string_view token) const {
    fail_at_line(
        path_, cursor_.line_number(),
        e.name + " " + std::to_string(index) + ": '" + std::string(token) + "' is not a number");
  }

  std::int64_t integer(std::size_t t, const PlyElement& e, std::uint64_t index) const {
    std::int64_t value = 0;
    if (!io_detail::parse_int(tokens_[t], value)) {
      fail_at_line(path_, cursor_.line_number(),
                   e.name + " " + std::to_string(index) + ": '" + std::string(tokens_[t]) +
                       "' is not an integer");
    }
    return value;
  }

  /// Length of the list whose count is token t; checks that its items are on the line.
  std::size_t list_length(const PlyProperty& prop, const PlyElement& e, std::uint64_t index,
                          std::size_t t) const {
    need(t + 1, e, index);
    const std::int64_t n = integer(t, e, index);
    if (n < 0) {
      fail_at_line(
          path_, cursor_.line_number(),
          e.name + " " + std::to_string(index) + ": negative length of list '" + prop.name + "'");
    }
    need(t + 1 + static_cast<std::size_t>(n), e, index);
    return static_cast<std::size_t>(n);
  }

  void read_polygon(const PlyElement& e, std::size_t first, std::size_t n, std::uint64_t f,
                    std::int64_t vertex_count, FaceLists kind, std::vector<std::int32_t>& corners,
                    io_detail::TriangleCollector& triangles) const {
    const std::size_t line = cursor_.line_number();
    check_list_length(path_, "line " + std::to_string(line), static_cast<std::int64_t>(n), f, kind);
    corners.resize(n);
    for (std::size_t c = 0; c < n; ++c) {
      std::int64_t v = 0;
      if (!io_detail::parse_int(tokens_[first + c], v)) {
        fail_at_line(path_, line,
                     e.name + " " + std::to_string(f) + ": '" + std::string(tokens_[first + c]) +
                         "' is not a vertex index");
      }
      if (!valid_corner(v, vertex_count, kind)) {
        fail_at_line(path_, line, bad_corner(e, f, v, vertex_count));
      }
      corners[c] = static_cast<std::int32_t>(v);
    }
    add_face_list(corners, f, kind, triangles);
  }

  const std::filesystem::path& path_;
  io_detail::LineCursor cursor_;
  std::size_t size_;
  std::vector<std::string_view> tokens_;
};

/// Where the ascii body's elements start, counted in lines with tokens (elements without
/// properties take no line), and each face element's list property.
struct AsciiLayout {
  std::vector<std::uint64_t> start;  // per header element, then the total
  std::vector<std::size_t> list_prop;
};

/// The elements whose lines fall in one run of the ascii body; `g` counts the lines with tokens
/// before the run.
void read_ascii_run(const std::filesystem::path& path, const PlyHeader& header,
                    const BodyPlan& plan, const AsciiLayout& layout, std::string_view text,
                    std::uint64_t g, Mesh& mesh, io_detail::TriangleCollector& triangles) {
  AsciiBody body(path, text, 1);
  std::vector<std::int32_t> corners;
  std::size_t j = 0;
  for (; g < layout.start.back() && body.next_line(); ++g) {
    while (layout.start[j + 1] <= g) ++j;
    const PlyElement& e = header.elements[j];
    const std::uint64_t i = g - layout.start[j];
    const ElementRole role = plan.element_roles[j];
    if (role == ElementRole::vertices) {
      body.read_vertex(e, plan.roles, i, mesh.V.data(), plan.has_normals ? mesh.N.data() : nullptr);
    } else if (role == ElementRole::faces || role == ElementRole::strips) {
      body.read_face(e, layout.list_prop[j], plan.vertex_count, face_lists(role, plan), i, corners,
                     triangles);
    } else {
      body.check_element(e, i);
    }
  }
}

}  // namespace

std::optional<Mesh> read_ascii_runs(const std::filesystem::path& path, const PlyHeader& header,
                                    const BodyPlan& plan, std::string_view body, int threads,
                                    std::size_t run_bytes) {
  const std::vector<std::size_t> cuts = io_detail::line_aligned_cuts(body, run_bytes);
  const std::size_t runs = cuts.size() - 1;
  if (runs < 2 || detail::thread_count(threads) < 2) return std::nullopt;
  AsciiLayout layout{{0}, {}};
  for (std::size_t j = 0; j < header.elements.size(); ++j) {
    const PlyElement& e = header.elements[j];
    const bool text = !e.properties.empty();
    // Counts the serial read's check_fits would refuse (the lines counted below always fit).
    if (text && e.count > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
      return std::nullopt;
    }
    std::size_t list_prop = 0;
    if (plan.element_roles[j] == ElementRole::faces ||
        plan.element_roles[j] == ElementRole::strips) {
      try {
        list_prop = face_list_property(path, e);
      } catch (const IoError&) {
        return std::nullopt;
      }
    }
    layout.list_prop.push_back(list_prop);
    layout.start.push_back(layout.start.back() + (text ? e.count : 0));
  }
  const auto run = [&](std::size_t r) { return body.substr(cuts[r], cuts[r + 1] - cuts[r]); };
  const std::vector<std::int64_t> first =  // lines with tokens before each run
      io_detail::lines_before_runs(body, cuts, threads, io_detail::has_token);
  // Fewer element lines than declared, or more: the serial read reports where.
  if (static_cast<std::uint64_t>(first.back()) != layout.start.back()) return std::nullopt;

  Mesh mesh;
  for (std::size_t j = 0; j < header.elements.size(); ++j) {
    if (plan.element_roles[j] == ElementRole::vertices) {
      allocate_vertices(path, mesh, header.elements[j], plan.has_normals);
    } else if (plan.element_roles[j] == ElementRole::faces) {
      io_detail::require_memory_for(path, header.elements[j].count, io_detail::kTriangleBytes,
                                    "faces");
    }
  }
  const bool read = io_detail::read_runs_joined(
      runs, threads, mesh, [&](std::size_t r, io_detail::TriangleCollector& triangles) {
        read_ascii_run(path, header, plan, layout, run(r), static_cast<std::uint64_t>(first[r]),
                       mesh, triangles);
      });
  if (!read) return std::nullopt;
  return mesh;
}

Mesh read_ascii_body(const std::filesystem::path& path, std::string_view data,
                     const PlyHeader& header, const BodyPlan& plan, int threads,
                     std::size_t chunk_bytes) {
  const std::string_view text = data.substr(header.body_offset);
  if (std::optional<Mesh> mesh = read_ascii_runs(path, header, plan, text, threads, chunk_bytes)) {
    return std::move(*mesh);
  }
  AsciiBody body(path, text, header.body_line);
  Mesh mesh = read_body(path, header, plan, body);
  body.check_end(header);
  return mesh;
}

}  // namespace focal::io_detail::ply
