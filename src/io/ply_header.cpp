// The PLY header: its lines parsed into elements and properties, and what they say about the
// body (which element is read how, where each vertex property goes).

#include <algorithm>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "io/file_bytes.h"
#include "io/ply.h"
#include "io/ply_read.h"
#include "io/text_scan.h"

namespace focal::io_detail::ply {
namespace {

PlyProperty parse_property_line(const std::filesystem::path& path, std::size_t line,
                                const std::vector<std::string_view>& tokens) {
  PlyProperty prop;
  auto type_of = [&](std::string_view name) {
    Scalar t{};
    if (!parse_scalar_type(name, t)) {
      fail_at_line(path, line, "unknown property type '" + std::string(name) + "'");
    }
    return t;
  };
  if (tokens.size() >= 2 && tokens[1] == "list") {
    if (tokens.size() != 5) {
      fail_at_line(path, line, "expected 'property list <count type> <item type> <name>'");
    }
    prop.is_list = true;
    prop.count_type = type_of(tokens[2]);
    prop.type = type_of(tokens[3]);
    prop.name = tokens[4];
    if (!is_integer(prop.count_type)) {
      fail_at_line(path, line, "list count type must be an integer type");
    }
    return prop;
  }
  if (tokens.size() != 3) fail_at_line(path, line, "expected 'property <type> <name>'");
  prop.type = type_of(tokens[1]);
  prop.name = tokens[2];
  return prop;
}

}  // namespace

PlyHeader parse_header(const std::filesystem::path& path, std::string_view data) {
  io_detail::LineCursor cursor(data);
  std::string_view line;
  std::vector<std::string_view> tokens;
  // Trailing blanks are allowed here as on every header line ("ply \n" from some writers).
  if (!cursor.next(line) || (io_detail::split_tokens(line, tokens), tokens.size() != 1) ||
      tokens[0] != "ply" || line.substr(0, 3) != "ply") {
    fail(path, "not a PLY file (first line is not 'ply')");
  }
  PlyHeader header;
  bool have_format = false;
  while (cursor.next(line)) {
    const std::size_t n = cursor.line_number();
    io_detail::split_tokens(line, tokens);
    if (tokens.empty()) continue;
    const std::string_view key = tokens[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header") {
      if (!have_format) fail_at_line(path, n, "end_header before the format line");
      header.body_offset = cursor.offset();
      header.body_line = n + 1;
      return header;
    }
    if (key == "format") {
      if (tokens.size() != 3) fail_at_line(path, n, "expected 'format <encoding> 1.0'");
      if (tokens[1] == "ascii") {
        header.encoding = PlyEncoding::ascii;
      } else if (tokens[1] == "binary_little_endian") {
        header.encoding = PlyEncoding::binary_little_endian;
      } else if (tokens[1] == "binary_big_endian") {
        header.encoding = PlyEncoding::binary_big_endian;
      } else {
        fail_at_line(path, n, "unknown format '" + std::string(tokens[1]) + "'");
      }
      // 1.0 is the only PLY version there is; another is not a file this reader understands.
      if (tokens[2] != "1.0" && tokens[2] != "1") {
        fail_at_line(path, n, "PLY version '" + std::string(tokens[2]) + "': only 1.0 is known");
      }
      have_format = true;
    } else if (key == "element") {
      std::int64_t count = 0;
      if (tokens.size() != 3 || !io_detail::parse_int(tokens[2], count) || count < 0) {
        fail_at_line(path, n, "expected 'element <name> <count>' with a count >= 0");
      }
      header.elements.push_back({std::string(tokens[1]), static_cast<std::uint64_t>(count), {}});
    } else if (key == "property") {
      if (header.elements.empty()) fail_at_line(path, n, "property before any element");
      header.elements.back().properties.push_back(parse_property_line(path, n, tokens));
    } else {
      fail_at_line(path, n, "unknown header keyword '" + std::string(key) + "'");
    }
  }
  fail(path, "the header has no end_header line");
}

std::vector<int> vertex_roles(const std::filesystem::path& path, const PlyElement& vertex,
                              bool& has_normals) {
  static constexpr std::string_view kNames[6] = {"x", "y", "z", "nx", "ny", "nz"};
  static constexpr std::string_view kPclNames[6] = {"x",        "y",        "z",
                                                    "normal_x", "normal_y", "normal_z"};
  std::vector<int> roles(vertex.properties.size(), -1);
  int found[6] = {-1, -1, -1, -1, -1, -1};
  for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
    const auto& p = vertex.properties[i];
    for (int r = 0; r < 6; ++r) {
      if ((p.name == kNames[r] || p.name == kPclNames[r]) && !p.is_list && found[r] < 0) {
        found[r] = static_cast<int>(i);
        roles[i] = r;
      }
    }
  }
  for (int r = 0; r < 3; ++r) {
    if (found[r] < 0) {
      fail(path, "the vertex element has no scalar property '" + std::string(kNames[r]) + "'");
    }
  }
  has_normals = found[3] >= 0 && found[4] >= 0 && found[5] >= 0;
  if (!has_normals) {
    for (int& r : roles) r = r >= 3 ? -1 : r;
  }
  return roles;
}

std::size_t face_list_property(const std::filesystem::path& path, const PlyElement& face) {
  for (std::size_t i = 0; i < face.properties.size(); ++i) {
    const auto& p = face.properties[i];
    if (p.name == "vertex_indices" || p.name == "vertex_index") {
      if (!p.is_list) fail(path, face.name + " property '" + p.name + "' is not a list");
      if (!is_integer(p.type)) {
        fail(path, face.name + " property '" + p.name + "' has non-integer items");
      }
      return i;
    }
  }
  fail(path,
       "the " + face.name + " element has no list property 'vertex_indices' or 'vertex_index'");
}

void add_face_list(const std::vector<std::int32_t>& corners, std::uint64_t f, FaceLists kind,
                   io_detail::TriangleCollector& triangles) {
  const auto source = kind.first_source + static_cast<std::int32_t>(f);
  if (kind.strips) {
    triangles.add_strip(corners.data(), corners.size(), source);
  } else {
    triangles.add_polygon(corners.data(), corners.size(), source);
  }
}

void check_list_length(const std::filesystem::path& path, const std::string& where, std::int64_t n,
                       std::uint64_t f, FaceLists kind) {
  if (!kind.strips && n < 3) {
    throw IoError(path.string() + ": " + where + ": face " + std::to_string(f) + " has " +
                  std::to_string(n) + " vertices; a face needs at least 3");
  }
}

bool valid_corner(std::int64_t v, std::int64_t vertex_count, FaceLists kind) {
  return (v >= 0 && v < vertex_count) || (kind.strips && v == -1);
}

std::string bad_corner(const PlyElement& e, std::uint64_t f, std::int64_t v,
                       std::int64_t vertex_count) {
  return e.name + " " + std::to_string(f) + " refers to vertex " + std::to_string(v) +
         " but there are " + std::to_string(vertex_count) + " vertices";
}

BodyPlan plan_body(const std::filesystem::path& path, const PlyHeader& header) {
  const auto element_named = [&](std::string_view name) {
    return std::find_if(header.elements.begin(), header.elements.end(),
                        [name](const PlyElement& e) { return e.name == name; });
  };
  const auto vertex_it = element_named("vertex");
  if (vertex_it == header.elements.end()) fail(path, "the header has no vertex element");
  BodyPlan plan;
  plan.roles = vertex_roles(path, *vertex_it, plan.has_normals);
  plan.vertex_count = static_cast<std::int64_t>(vertex_it->count);
  const auto face_it = element_named("face");
  plan.has_strips = element_named("tristrips") != header.elements.end();
  plan.faces_before_strips =
      static_cast<std::int32_t>(face_it == header.elements.end() ? 0 : face_it->count);
  bool vertices = false, faces = false, strips = false;
  for (const PlyElement& e : header.elements) {
    ElementRole role = ElementRole::skip;
    if (e.name == "vertex" && !std::exchange(vertices, true)) role = ElementRole::vertices;
    if (e.name == "face" && !std::exchange(faces, true)) role = ElementRole::faces;
    if (e.name == "tristrips" && !std::exchange(strips, true)) role = ElementRole::strips;
    plan.element_roles.push_back(role);
  }
  return plan;
}

void allocate_vertices(const std::filesystem::path& path, Mesh& mesh, const PlyElement& e,
                       bool normals) {
  io_detail::require_memory_for(
      path, e.count, io_detail::kVertexBytes + (normals ? io_detail::kNormalBytes : 0), "vertices");
  mesh.V.resize(static_cast<Eigen::Index>(e.count), 3);
  detail::advise_huge_pages(mesh.V.data(), sizeof(double) * mesh.V.size());
  if (normals) {
    mesh.N.resize(static_cast<Eigen::Index>(e.count), 3);
    detail::advise_huge_pages(mesh.N.data(), sizeof(double) * mesh.N.size());
  }
}

FaceLists face_lists(ElementRole role, const BodyPlan& plan) {
  if (role == ElementRole::strips)
    return {.strips = true, .first_source = plan.faces_before_strips};
  return {};
}

}  // namespace focal::io_detail::ply
