#pragma once
/// \file ply_read.h
/// The PLY reader's pieces, internal to io/: the header as parsed and what it says about the
/// body (ply_header.cpp), the element loop that the binary (ply_binary.cpp) and ascii
/// (ply_ascii.cpp) bodies share, and their entry points for read_ply / parse_ply (ply_read.cpp)
/// and for the binary reader by record ranges (ply_records.cpp). Scalar types, their names and
/// byte order: io/ply.h.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "focal/core/mesh.h"
#include "io/bytes.h"
#include "io/file_bytes.h"
#include "io/format_readers.h"
#include "io/ply.h"
#include "io/text_scan.h"

namespace focal::io_detail::ply {

struct PlyProperty {
  std::string name;
  Scalar type = Scalar::float32;  ///< the item type for a list
  bool is_list = false;
  Scalar count_type = Scalar::uint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;

  /// Bytes of the smallest binary element: every list empty.
  [[nodiscard]] std::size_t min_binary_bytes() const {
    std::size_t bytes = 0;
    for (const auto& p : properties) bytes += scalar_size(p.is_list ? p.count_type : p.type);
    return bytes;
  }
  [[nodiscard]] bool fixed_size() const {
    return std::none_of(properties.begin(), properties.end(),
                        [](const PlyProperty& p) { return p.is_list; });
  }
};

enum class PlyEncoding { ascii, binary_little_endian, binary_big_endian };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;  ///< first byte after the end_header line
  std::size_t body_line = 0;    ///< line number of the first body line (ascii)
};

/// The header of `data` (a whole file, or at least its header): its encoding, elements and
/// properties, and where the body starts.
/// \throw IoError naming the line for a header that is not PLY or that the reader cannot read.
PlyHeader parse_header(const std::filesystem::path& path, std::string_view data);

/// Where each property of the vertex element goes: 0..2 x y z, 3..5 nx ny nz (or PCL's
/// normal_x normal_y normal_z), -1 skipped; the first property of a role takes it.
/// \throw IoError when x, y or z is missing.
std::vector<int> vertex_roles(const std::filesystem::path& path, const PlyElement& vertex,
                              bool& has_normals);

/// Index of the vertex list property of a face or tristrips element.
/// \throw IoError when there is none, or it is not a list of integers.
std::size_t face_list_property(const std::filesystem::path& path, const PlyElement& face);

/// How a face list is read: one polygon per element (`face`), or triangle strips
/// (`tristrips`: each list a strip, -1 starting a new one).
struct FaceLists {
  bool strips = false;
  std::int32_t first_source = 0;  ///< Mesh::face_source of the element's first list
};

/// Adds list `f` of a face list element, checked, to `triangles`.
void add_face_list(const std::vector<std::int32_t>& corners, std::uint64_t f, FaceLists kind,
                   io_detail::TriangleCollector& triangles);

/// Throws unless list `f` of element `e` has enough corners for a face (strips may be short).
void check_list_length(const std::filesystem::path& path, const std::string& where, std::int64_t n,
                       std::uint64_t f, FaceLists kind);

/// Whether v is a corner index: in [0, #V), or -1 (a restart) in a strip.
bool valid_corner(std::int64_t v, std::int64_t vertex_count, FaceLists kind);

/// "<element> <f> refers to vertex <v> but there are <vertex_count> vertices".
std::string bad_corner(const PlyElement& e, std::uint64_t f, std::int64_t v,
                       std::int64_t vertex_count);

/// A binary scalar of type t converted to Out. Integer reads (indices, list counts) only see
/// integer types: the header parser rejects float index and count types.
template <class Out>
Out load_as(const unsigned char* p, Scalar t, bool swap) {
  switch (t) {
    case Scalar::int8:
      return static_cast<Out>(load<std::int8_t>(p, swap));
    case Scalar::uint8:
      return static_cast<Out>(load<std::uint8_t>(p, swap));
    case Scalar::int16:
      return static_cast<Out>(load<std::int16_t>(p, swap));
    case Scalar::uint16:
      return static_cast<Out>(load<std::uint16_t>(p, swap));
    case Scalar::int32:
      return static_cast<Out>(load<std::int32_t>(p, swap));
    case Scalar::uint32:
      return static_cast<Out>(load<std::uint32_t>(p, swap));
    case Scalar::int64:
      return static_cast<Out>(load<std::int64_t>(p, swap));
    case Scalar::uint64: {
      // Saturated, so that an index or count beyond 2^63 stays out of range, not negative.
      const std::uint64_t v = load<std::uint64_t>(p, swap);
      return static_cast<Out>(std::min<std::uint64_t>(v, std::numeric_limits<std::int64_t>::max()));
    }
    case Scalar::float32:
      if constexpr (std::is_floating_point_v<Out>) return static_cast<Out>(load<float>(p, swap));
      break;
    case Scalar::float64:
      if constexpr (std::is_floating_point_v<Out>) return static_cast<Out>(load<double>(p, swap));
      break;
  }
  return Out{0};
}

/// What read_body does with an element: the first `vertex`, `face` and `tristrips` elements are
/// read, any other element (and any repeat of those) is skipped.
enum class ElementRole { vertices, faces, strips, skip };

/// What the header says about the body, before any of it is read.
struct BodyPlan {
  std::vector<int> roles;  // vertex_roles
  bool has_normals = false;
  std::int64_t vertex_count = 0;
  std::int32_t faces_before_strips = 0;  // strip triangles are numbered after the faces
  bool has_strips = false;
  std::vector<ElementRole> element_roles;  // per header element
};

/// What the header says about the body. \throw IoError without a vertex element (vertex_roles).
BodyPlan plan_body(const std::filesystem::path& path, const PlyHeader& header);

/// mesh.V (and mesh.N) for the vertex element, advised onto huge pages before they are written.
/// \throw IoError when the machine cannot hold them (io_detail::require_memory_for).
void allocate_vertices(const std::filesystem::path& path, Mesh& mesh, const PlyElement& e,
                       bool normals);

/// How the face lists of an element of `role` are read.
FaceLists face_lists(ElementRole role, const BodyPlan& plan);

class BinaryBody;

/// Reads every element in file order with `Body` (BinaryBody or AsciiBody).
template <class Body>
Mesh read_body(const std::filesystem::path& path, const PlyHeader& header, const BodyPlan& plan,
               Body& body) {
  Mesh mesh;
  io_detail::TriangleCollector triangles;
  bool faces_direct = false;  // read_triangle_faces() filled mesh.F and mesh.face_source
  for (std::size_t j = 0; j < header.elements.size(); ++j) {
    const PlyElement& e = header.elements[j];
    const ElementRole role = plan.element_roles[j];
    body.check_fits(e);
    if (role == ElementRole::vertices) {
      allocate_vertices(path, mesh, e, plan.has_normals);
      body.read_vertices(e, plan.roles, mesh.V.data(), plan.has_normals ? mesh.N.data() : nullptr);
    } else if (role == ElementRole::faces || role == ElementRole::strips) {
      if (role == ElementRole::faces) {
        io_detail::require_memory_for(path, e.count, io_detail::kTriangleBytes, "faces");
      }
      const std::size_t list_prop = face_list_property(path, e);
      if constexpr (std::is_same_v<Body, BinaryBody>) {
        if (role == ElementRole::faces && !plan.has_strips) {
          faces_direct = body.read_triangle_faces(e, list_prop, plan.vertex_count, mesh);
        }
      }
      if (!faces_direct) {
        if (role == ElementRole::faces) triangles.reserve(static_cast<std::size_t>(e.count));
        body.read_faces(e, list_prop, plan.vertex_count, face_lists(role, plan), triangles);
      }
    } else {
      body.skip_element(e);
    }
  }
  if (!faces_direct) triangles.move_into(mesh);
  return mesh;
}

/// The binary body of `data` (the whole file) read with BinaryBody, its parallel passes on
/// `threads` threads.
Mesh read_binary_body(const std::filesystem::path& path, std::string_view data,
                      const PlyHeader& header, const BodyPlan& plan, int threads);

/// The ascii body of `data` (the whole file): in parallel runs of `chunk_bytes`
/// (read_ascii_runs), else serially, which gives the exact error.
Mesh read_ascii_body(const std::filesystem::path& path, std::string_view data,
                     const PlyHeader& header, const BodyPlan& plan, int threads,
                     std::size_t chunk_bytes);

/// The ascii body read as runs of lines in parallel, as parse_obj reads an OBJ: a first pass
/// counts each run's lines with tokens, so each run knows the element (and its index) its first
/// line holds; a second reads the runs with AsciiBody's own read_vertex / read_face /
/// check_element. Nothing when the body is too small to split, ends early, or a run meets an
/// error (or a face element lacks its list property): the serial read then gives the exact error.
std::optional<Mesh> read_ascii_runs(const std::filesystem::path& path, const PlyHeader& header,
                                    const BodyPlan& plan, std::string_view body, int threads,
                                    std::size_t run_bytes);

}  // namespace focal::io_detail::ply
