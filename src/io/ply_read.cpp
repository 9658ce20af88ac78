// PLY reading: ascii, binary little and big endian. The types, names and byte order shared with
// the writer are in io/ply.h.

#include <algorithm>
#include <bit>
#include <limits>
#include <optional>
#include <type_traits>
#include <utility>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/file_bytes.h"
#include "io/format_readers.h"
#include "io/ply.h"
#include "io/text_scan.h"

namespace focal {
namespace {

using io_detail::fail;
using io_detail::fail_at_line;
using io_detail::fail_at_offset;
using io_detail::ply::is_integer;
using io_detail::load;
using io_detail::ply::parse_scalar_type;
using io_detail::ply::Scalar;
using io_detail::ply::scalar_size;

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

/// Where each property of the vertex element goes: 0..2 x y z, 3..5 nx ny nz (or PCL's
/// normal_x normal_y normal_z), -1 skipped; the first property of a role takes it.
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

/// Index of the vertex list property of a face or tristrips element.
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

/// How a face list is read: one polygon per element (`face`), or triangle strips
/// (`tristrips`: each list a strip, -1 starting a new one).
struct FaceLists {
  bool strips = false;
  std::int32_t first_source = 0;  ///< Mesh::face_source of the element's first list
};

/// Adds list `f` of a face list element, checked, to `triangles`.
void add_face_list(const std::vector<std::int32_t>& corners, std::uint64_t f, FaceLists kind,
                   io_detail::TriangleCollector& triangles) {
  const auto source = kind.first_source + static_cast<std::int32_t>(f);
  if (kind.strips) {
    triangles.add_strip(corners.data(), corners.size(), source);
  } else {
    triangles.add_polygon(corners.data(), corners.size(), source);
  }
}

/// Throws unless list `f` of element `e` has enough corners for a face (strips may be short).
void check_list_length(const std::filesystem::path& path, const std::string& where, std::int64_t n,
                       std::uint64_t f, FaceLists kind) {
  if (!kind.strips && n < 3) {
    throw IoError(path.string() + ": " + where + ": face " + std::to_string(f) + " has " +
                  std::to_string(n) + " vertices; a face needs at least 3");
  }
}

/// Whether v is a corner index: in [0, #V), or -1 (a restart) in a strip.
bool valid_corner(std::int64_t v, std::int64_t vertex_count, FaceLists kind) {
  return (v >= 0 && v < vertex_count) || (kind.strips && v == -1);
}

std::string bad_corner(const PlyElement& e, std::uint64_t f, std::int64_t v,
                       std::int64_t vertex_count) {
  return e.name + " " + std::to_string(f) + " refers to vertex " + std::to_string(v) +
         " but there are " + std::to_string(vertex_count) + " vertices";
}

// ---------------------------------------------------------------------------------------------
// Binary body

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

class BinaryBody {
 public:
  BinaryBody(const std::filesystem::path& path, std::string_view data, std::size_t offset,
             bool swap, int threads)
      : path_(path),
        begin_(reinterpret_cast<const unsigned char*>(data.data())),
        p_(begin_ + offset),
        end_(begin_ + data.size()),
        swap_(swap),
        threads_(threads) {}

  /// Rejects a count that cannot fit in the rest of the file, before anything is allocated.
  void check_fits(const PlyElement& e) const {
    const std::size_t min_bytes = e.min_binary_bytes();
    const auto remaining = static_cast<std::uint64_t>(end_ - p_);
    if (min_bytes > 0 && e.count > remaining / min_bytes && e.fixed_size()) {
      // Fixed-size elements: say exactly which one the file ends in.
      const std::uint64_t complete = remaining / min_bytes;
      fail_at_offset(path_, offset() + complete * min_bytes,
                     "file ends inside " + e.name + " " + std::to_string(complete) + " of " +
                         std::to_string(e.count));
    }
    io_detail::check_count_fits(path_, "byte offset " + std::to_string(offset()), e.count,
                                min_bytes, remaining, e.name + " elements");
  }

  void read_vertices(const PlyElement& e, const std::vector<int>& roles, double* V, double* N) {
    if (e.fixed_size()) {
      read_fixed_vertices(e, roles, V, N);
      return;
    }
    for (std::uint64_t i = 0; i < e.count; ++i) {
      const unsigned char* start = p_;
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const auto& prop = e.properties[k];
        if (prop.is_list) {
          skip_list(prop, e, i, start);
          continue;
        }
        require(scalar_size(prop.type), e, i, start);
        const int role = roles[k];
        if (role >= 0) {
          const double value = load_as<double>(p_, prop.type, swap_);
          if (role < 3) {
            V[3 * i + role] = value;
          } else {
            N[3 * i + role - 3] = value;
          }
        }
        p_ += scalar_size(prop.type);
      }
    }
  }

  /// Reads the face element straight into mesh.F and mesh.face_source, in parallel, when every
  /// face is a triangle stored at a fixed stride (no other list property) and every index is in
  /// range. Returns false, having read and changed nothing, otherwise: read_faces() then gives
  /// the exact results and error messages of the serial reader.
  bool read_triangle_faces(const PlyElement& e, std::size_t list_prop, std::int64_t vertex_count,
                           Mesh& mesh) {
    std::size_t count_offset = 0;
    std::size_t stride = 0;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const auto& prop = e.properties[k];
      if (k == list_prop) {
        count_offset = stride;
        stride += scalar_size(prop.count_type) + 3 * scalar_size(prop.type);
      } else if (prop.is_list) {
        return false;
      } else {
        stride += scalar_size(prop.type);
      }
    }
    const auto remaining = static_cast<std::uint64_t>(end_ - p_);
    if (e.count == 0 || e.count > remaining / stride ||
        e.count > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
      return false;
    }
    const PlyProperty& list = e.properties[list_prop];
    const std::size_t count_bytes = scalar_size(list.count_type);
    const std::size_t item = scalar_size(list.type);
    // `list uchar int` (or uint) in the host's byte order, as focal and most writers store it.
    const bool common = !swap_ && list.count_type == Scalar::uint8 &&
                        (list.type == Scalar::int32 || list.type == Scalar::uint32);
    const auto faces = static_cast<std::int64_t>(e.count);
    RowMatrixX3i F(faces, 3);
    Eigen::VectorXi source(faces);
    detail::advise_huge_pages(F.data(), sizeof(std::int32_t) * F.size());
    detail::advise_huge_pages(source.data(), sizeof(std::int32_t) * source.size());
    std::int32_t* corners = F.data();
    const unsigned char* first = p_ + count_offset;
    // One flag per block of faces (blocks independent of the thread count): the first pass
    // both checks and converts, so a valid file is read once.
    constexpr std::int64_t kBlock = 1 << 14;
    std::vector<unsigned char> bad(static_cast<std::size_t>((faces + kBlock - 1) / kBlock), 0);
    detail::parallel_for_blocks(faces, kBlock, threads_, [&](std::int64_t begin, std::int64_t end) {
      bool ok = true;
      if (common) {
        for (std::int64_t f = begin; f < end; ++f) {
          const unsigned char* rec = first + static_cast<std::size_t>(f) * stride;
          ok &= rec[0] == 3;
          for (int c = 0; c < 3; ++c) {
            const std::int64_t v = list.type == Scalar::int32
                                       ? std::int64_t{load<std::int32_t>(rec + 1 + 4 * c, false)}
                                       : std::int64_t{load<std::uint32_t>(rec + 1 + 4 * c, false)};
            ok &= v >= 0 && v < vertex_count;
            corners[3 * f + c] = static_cast<std::int32_t>(v);
          }
          source[f] = static_cast<std::int32_t>(f);
        }
      } else {
        for (std::int64_t f = begin; f < end; ++f) {
          const unsigned char* rec = first + static_cast<std::size_t>(f) * stride;
          ok &= load_as<std::int64_t>(rec, list.count_type, swap_) == 3;
          rec += count_bytes;
          for (int c = 0; c < 3; ++c) {
            const std::int64_t v = load_as<std::int64_t>(rec + c * item, list.type, swap_);
            ok &= v >= 0 && v < vertex_count;
            corners[3 * f + c] = static_cast<std::int32_t>(v);
          }
          source[f] = static_cast<std::int32_t>(f);
        }
      }
      if (!ok) bad[static_cast<std::size_t>(begin / kBlock)] = 1;
    });
    if (std::find(bad.begin(), bad.end(), 1) != bad.end()) return false;
    mesh.F = std::move(F);
    mesh.face_source = std::move(source);
    p_ += e.count * stride;
    return true;
  }

  void read_faces(const PlyElement& e, std::size_t list_prop, std::int64_t vertex_count,
                  FaceLists kind, io_detail::TriangleCollector& triangles) {
    std::vector<std::int32_t> corners;
    for (std::uint64_t f = 0; f < e.count; ++f) {
      const unsigned char* start = p_;
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const auto& prop = e.properties[k];
        if (k != list_prop) {
          if (prop.is_list) {
            skip_list(prop, e, f, start);
          } else {
            require(scalar_size(prop.type), e, f, start);
            p_ += scalar_size(prop.type);
          }
          continue;
        }
        const std::int64_t n = read_count(prop, e, f, start);
        check_list_length(path_, "byte offset " + std::to_string(offset_of(start)), n, f, kind);
        const std::size_t item = scalar_size(prop.type);
        require(static_cast<std::size_t>(n) * item, e, f, start);
        corners.resize(static_cast<std::size_t>(n));
        for (std::int64_t c = 0; c < n; ++c) {
          const std::int64_t v = load_as<std::int64_t>(p_, prop.type, swap_);
          if (!valid_corner(v, vertex_count, kind)) {
            fail_at_offset(path_, offset_of(start),
                           bad_corner(e, f, v, vertex_count) +
                               byte_order_hint(p_, prop.type, vertex_count, kind));
          }
          corners[static_cast<std::size_t>(c)] = static_cast<std::int32_t>(v);
          p_ += item;
        }
        add_face_list(corners, f, kind, triangles);
      }
    }
  }

  void skip_element(const PlyElement& e) {
    if (e.fixed_size()) {
      p_ += e.count * e.min_binary_bytes();  // check_fits() made sure this is inside the file
      return;
    }
    for (std::uint64_t i = 0; i < e.count; ++i) {
      const unsigned char* start = p_;
      for (const auto& prop : e.properties) {
        if (prop.is_list) {
          skip_list(prop, e, i, start);
        } else {
          require(scalar_size(prop.type), e, i, start);
          p_ += scalar_size(prop.type);
        }
      }
    }
  }

  [[nodiscard]] std::uint64_t offset() const { return offset_of(p_); }

 private:
  /// Fixed-size records: check_fits() made sure all of them are in the file, so no record can
  /// fail and they are converted in parallel blocks.
  void read_fixed_vertices(const PlyElement& e, const std::vector<int>& roles, double* V,
                           double* N) {
    if (e.count == 0) return;  // V and N may be null: no column pointers to form
    struct Field {
      std::size_t offset;
      Scalar type;
      double* out;  ///< column base: out[3 * i]
    };
    Field fields[6];
    int used = 0;
    std::size_t offset = 0;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const int role = roles[k];
      if (role >= 0) {
        fields[used++] = {offset, e.properties[k].type, role < 3 ? V + role : N + role - 3};
      }
      offset += scalar_size(e.properties[k].type);
    }
    const std::size_t stride = offset;
    const unsigned char* first = p_;
    detail::parallel_for_blocks(
        static_cast<std::int64_t>(e.count), std::int64_t{1} << 14, threads_,
        [&](std::int64_t begin, std::int64_t end) {
          // Field by field, so that the type switch is decided once per block and field.
          for (int k = 0; k < used; ++k) {
            const Field& field = fields[k];
            const unsigned char* rec = first + field.offset;
            switch (field.type) {
              case Scalar::float64:
                for (std::int64_t i = begin; i < end; ++i) {
                  field.out[3 * i] =
                      load<double>(rec + static_cast<std::size_t>(i) * stride, swap_);
                }
                break;
              case Scalar::float32:
                for (std::int64_t i = begin; i < end; ++i) {
                  field.out[3 * i] = load<float>(rec + static_cast<std::size_t>(i) * stride, swap_);
                }
                break;
              default:
                for (std::int64_t i = begin; i < end; ++i) {
                  field.out[3 * i] = load_as<double>(rec + static_cast<std::size_t>(i) * stride,
                                                     field.type, swap_);
                }
                break;
            }
          }
        });
    p_ += e.count * stride;
  }

  /// " (wrong byte order ...?)" when the index at p, out of range, would be in range read in the
  /// other byte order; else "".
  [[nodiscard]] std::string byte_order_hint(const unsigned char* p, Scalar t,
                                            std::int64_t vertex_count, FaceLists kind) const {
    if (scalar_size(t) == 1 ||
        !valid_corner(load_as<std::int64_t>(p, t, !swap_), vertex_count, kind)) {
      return "";
    }
    return " (wrong byte order? the header says binary_" +
           std::string(swap_ == (std::endian::native == std::endian::little) ? "big" : "little") +
           "_endian)";
  }

  [[nodiscard]] std::uint64_t offset_of(const unsigned char* p) const {
    return static_cast<std::uint64_t>(p - begin_);
  }

  /// Throws unless `bytes` more bytes of element `index` (which began at `start`) are present.
  void require(std::size_t bytes, const PlyElement& e, std::uint64_t index,
               const unsigned char* start) const {
    if (static_cast<std::size_t>(end_ - p_) < bytes) {
      fail_at_offset(path_, offset_of(start),
                     "file ends inside " + e.name + " " + std::to_string(index) + " of " +
                         std::to_string(e.count));
    }
  }

  std::int64_t read_count(const PlyProperty& prop, const PlyElement& e, std::uint64_t index,
                          const unsigned char* start) {
    require(scalar_size(prop.count_type), e, index, start);
    const std::int64_t n = load_as<std::int64_t>(p_, prop.count_type, swap_);
    p_ += scalar_size(prop.count_type);
    if (n < 0) {
      fail_at_offset(
          path_, offset_of(start),
          e.name + " " + std::to_string(index) + ": negative list length " + std::to_string(n));
    }
    // Each item takes a byte at least: a longer list cannot be in the file (and n * item size
    // could overflow for 64-bit counts).
    if (static_cast<std::uint64_t>(n) > static_cast<std::uint64_t>(end_ - p_)) {
      require(static_cast<std::size_t>(end_ - p_) + 1, e, index, start);
    }
    return n;
  }

  void skip_list(const PlyProperty& prop, const PlyElement& e, std::uint64_t index,
                 const unsigned char* start) {
    const std::int64_t n = read_count(prop, e, index, start);
    const std::size_t bytes = static_cast<std::size_t>(n) * scalar_size(prop.type);
    require(bytes, e, index, start);
    p_ += bytes;
  }

  const std::filesystem::path& path_;
  const unsigned char* begin_;
  const unsigned char* p_;
  const unsigned char* end_;
  bool swap_;
  int threads_;  ///< of the parallel passes over fixed-size records
};

// ---------------------------------------------------------------------------------------------
// Ascii body: one element per line, blank lines ignored.

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

/// mesh.V (and mesh.N) for the vertex element, advised onto huge pages before they are written.
void allocate_vertices(Mesh& mesh, const PlyElement& e, bool normals) {
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
      allocate_vertices(mesh, e, plan.has_normals);
      body.read_vertices(e, plan.roles, mesh.V.data(), plan.has_normals ? mesh.N.data() : nullptr);
    } else if (role == ElementRole::faces || role == ElementRole::strips) {
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

/// The ascii body read as runs of lines in parallel, as parse_obj reads an OBJ: a first pass
/// counts each run's lines with tokens, so each run knows the element (and its index) its first
/// line holds; a second reads the runs with AsciiBody's own read_vertex / read_face /
/// check_element. Nothing when the body is too small to split, ends early, or a run meets an
/// error (or a face element lacks its list property): the serial read then gives the exact error.
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
  if (static_cast<std::uint64_t>(first.back()) < layout.start.back()) return std::nullopt;

  Mesh mesh;
  for (std::size_t j = 0; j < header.elements.size(); ++j) {
    if (plan.element_roles[j] == ElementRole::vertices) {
      allocate_vertices(mesh, header.elements[j], plan.has_normals);
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

}  // namespace

namespace io_detail {

Mesh read_ply(const std::filesystem::path& path, int threads) {
  return parse_ply(path, read_whole_file(path), threads);
}

Mesh parse_ply(const std::filesystem::path& path, std::string_view data) {
  return parse_ply(path, data, 0);
}

Mesh parse_ply(const std::filesystem::path& path, std::string_view data, int threads) {
  return parse_ply(path, data, threads, kTextChunkBytes);
}

std::optional<Mesh> parse_ply_in_chunks(const std::filesystem::path& path, std::string_view data,
                                        int threads, std::size_t chunk_bytes) {
  const PlyHeader header = parse_header(path, data);
  if (header.encoding != PlyEncoding::ascii) return std::nullopt;
  const BodyPlan plan = plan_body(path, header);
  return read_ascii_runs(path, header, plan, data.substr(header.body_offset), threads, chunk_bytes);
}

Mesh parse_ply(const std::filesystem::path& path, std::string_view data, int threads,
               std::size_t chunk_bytes) {
  const PlyHeader header = parse_header(path, data);
  const BodyPlan plan = plan_body(path, header);
  if (header.encoding == PlyEncoding::ascii) {
    const std::string_view text = data.substr(header.body_offset);
    if (std::optional<Mesh> mesh =
            read_ascii_runs(path, header, plan, text, threads, chunk_bytes)) {
      return std::move(*mesh);
    }
    AsciiBody body(path, text, header.body_line);
    return read_body(path, header, plan, body);
  }
  const bool file_big = header.encoding == PlyEncoding::binary_big_endian;
  const bool host_big = std::endian::native == std::endian::big;
  BinaryBody body(path, data, header.body_offset, file_big != host_big, threads);
  return read_body(path, header, plan, body);
}

}  // namespace io_detail
}  // namespace focal
