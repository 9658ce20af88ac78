// PlyTriangleReader: a binary PLY triangle mesh read by ranges or sets of fixed-size records. The
// header is parsed by the reader's own parse_header and the vertex properties get the roles
// read_mesh gives them (io/ply_read.h), so that both read the same values from a file.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <fstream>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/file_bytes.h"
#include "io/ply.h"
#include "io/ply_read.h"

namespace focal {

using io_detail::fail;
using io_detail::fail_at_offset;
using io_detail::ply::load_as;
using io_detail::ply::PlyElement;
using io_detail::ply::PlyHeader;
using io_detail::ply::Scalar;
using io_detail::ply::scalar_size;

/// One scalar of a record: its byte offset in the record and its type.
struct RecordField {
  std::size_t offset = 0;
  Scalar type = Scalar::float64;
};

struct PlyTriangleReader::Layout {
  std::filesystem::path path;
  bool swap = false;  ///< the file's byte order is not the host's
  std::int64_t vertex_count = 0;
  std::int64_t face_count = 0;
  std::uint64_t vertex_offset = 0;  ///< of the first vertex record
  std::uint64_t vertex_stride = 0;
  RecordField position[3];
  bool has_normals = false;
  RecordField normal[3];
  std::uint64_t face_offset = 0;  ///< of the first face record
  std::uint64_t face_stride = 0;
  RecordField corner_count;  ///< the list's count
  RecordField corners;       ///< its first item
  PlyElement face;           ///< for messages
};

namespace {

/// Bytes read at a time: the most a read holds besides its result.
constexpr std::uint64_t kBlockBytes = std::uint64_t{1} << 20;
/// Ascending ids closer than this many bytes of records are read in one block.
constexpr std::uint64_t kGapBytes = std::uint64_t{1} << 16;

/// The file's first bytes up to and including the end_header line, parsed. The prefix grows until
/// it holds that line's terminator (or is the whole file, whose error parse_header then gives).
PlyHeader read_header(const std::filesystem::path& path, std::uint64_t size) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open for reading");
  std::string prefix;
  for (std::uint64_t want = std::min<std::uint64_t>(size, 1 << 16);;
       want = std::min(size, 4 * want)) {
    const std::size_t had = prefix.size();
    prefix.resize(static_cast<std::size_t>(want));
    in.read(prefix.data() + had, static_cast<std::streamsize>(want - had));
    if (static_cast<std::uint64_t>(in.gcount()) != want - had) fail(path, "read failed");
    if (want == size) return io_detail::ply::parse_header(path, prefix);
    try {
      const PlyHeader header = io_detail::ply::parse_header(path, prefix);
      if (header.body_offset < prefix.size()) return header;
    } catch (const IoError&) {  // perhaps only a prefix too short: read more
    }
  }
}

/// The fields of a fixed-size element's record, and its size.
std::uint64_t record_fields(const std::filesystem::path& path, const PlyElement& e,
                            std::size_t list_prop, std::vector<RecordField>& fields) {
  std::uint64_t offset = 0;
  for (std::size_t k = 0; k < e.properties.size(); ++k) {
    const auto& p = e.properties[k];
    if (p.is_list && k != list_prop) {
      fail(path, e.name + " property '" + p.name +
                     "' is a list: streaming reads fixed-size vertex and face records");
    }
    fields.push_back({static_cast<std::size_t>(offset), p.is_list ? p.count_type : p.type});
    offset += p.is_list ? scalar_size(p.count_type) + 3 * scalar_size(p.type) : scalar_size(p.type);
  }
  return offset;
}

void require_int32(const std::filesystem::path& path, const PlyElement& e) {
  if (e.count > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
    fail(path, "the header declares " + std::to_string(e.count) + " " + e.name +
                   " elements, more than 32-bit indices can address");
  }
}

/// offset + count * stride, saturated (a count no file can hold).
std::uint64_t after_records(std::uint64_t offset, std::uint64_t count, std::uint64_t stride) {
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  if (stride != 0 && count > (kMax - offset) / stride) return kMax;
  return offset + count * stride;
}

std::shared_ptr<const PlyTriangleReader::Layout> read_layout(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) fail(path, "no such file");
  if (!std::filesystem::is_regular_file(status)) fail(path, "not a regular file");
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot read its size");
  const PlyHeader header = read_header(path, size);
  if (header.encoding == io_detail::ply::PlyEncoding::ascii) {
    fail(path, "format ascii: streaming reads binary PLY only (read_mesh reads ascii)");
  }
  auto out = std::make_shared<PlyTriangleReader::Layout>();
  out->path = path;
  out->swap = (header.encoding == io_detail::ply::PlyEncoding::binary_big_endian) !=
              (std::endian::native == std::endian::big);
  const PlyElement* vertex = nullptr;
  const PlyElement* face = nullptr;
  for (const PlyElement& e : header.elements) {
    if (e.name == "tristrips") {
      fail(path, "a tristrips element: streaming reads the faces of the face element only");
    }
  }
  std::uint64_t offset = header.body_offset;
  std::uint64_t end = offset;
  for (const PlyElement& e : header.elements) {
    if (e.name == "vertex" && vertex == nullptr) {
      vertex = &e;
      out->vertex_offset = offset;
    } else if (e.name == "face" && face == nullptr) {
      face = &e;
      out->face_offset = offset;
    } else if (vertex != nullptr && face != nullptr) {
      break;  // the elements after both are not read
    } else if (!e.fixed_size()) {
      fail(path, "element '" + e.name +
                     "' before the vertices or faces has a list: streaming reads fixed-size "
                     "records");
    }
    if (&e == face) {
      std::vector<RecordField> fields;
      const std::size_t list = io_detail::ply::face_list_property(path, e);
      out->face_stride = record_fields(path, e, list, fields);
      out->corner_count = fields[list];
      out->corners = {fields[list].offset + scalar_size(e.properties[list].count_type),
                      e.properties[list].type};
      offset = after_records(offset, e.count, out->face_stride);
    } else {
      offset = after_records(offset, e.count, e.min_binary_bytes());
    }
    end = offset;
  }
  if (vertex == nullptr || face == nullptr) {
    fail(path, "streaming reads a mesh: the header needs a vertex and a face element");
  }
  require_int32(path, *vertex);
  require_int32(path, *face);
  bool has_normals = false;
  const std::vector<int> roles = io_detail::ply::vertex_roles(path, *vertex, has_normals);
  std::vector<RecordField> fields;
  out->vertex_stride = record_fields(path, *vertex, vertex->properties.size(), fields);
  for (std::size_t k = 0; k < roles.size(); ++k) {
    if (roles[k] >= 0 && roles[k] < 3) out->position[roles[k]] = fields[k];
    if (roles[k] >= 3) out->normal[roles[k] - 3] = fields[k];
  }
  out->has_normals = has_normals;
  out->vertex_count = static_cast<std::int64_t>(vertex->count);
  out->face_count = static_cast<std::int64_t>(face->count);
  out->face = *face;
  if (size < end) {
    fail(path, std::to_string(size) + " bytes, the header's elements need " + std::to_string(end) +
                   " (truncated, or faces that are not all triangles)");
  }
  return out;
}

void check_range(std::int64_t begin, std::int64_t end, std::int64_t count, const char* what) {
  if (begin < 0 || begin > end || end > count) {
    throw InvalidInput(std::string("PlyTriangleReader: ") + what + " " + std::to_string(begin) +
                       " .. " + std::to_string(end) + " are not in [0, " + std::to_string(count) +
                       ")");
  }
}

/// Reads records first .. first + count - 1 of `stride` bytes from `offset` on, a block at a time,
/// handing each to use(record index, its bytes).
template <class Use>
void for_each_record(std::ifstream& in, const std::filesystem::path& path, std::uint64_t offset,
                     std::uint64_t stride, std::int64_t first, std::int64_t count,
                     std::vector<unsigned char>& block, const Use& use) {
  const auto per_block =
      static_cast<std::int64_t>(std::max<std::uint64_t>(1, kBlockBytes / stride));
  for (std::int64_t b = 0; b < count; b += per_block) {
    const std::int64_t n = std::min(per_block, count - b);
    const std::uint64_t at = offset + static_cast<std::uint64_t>(first + b) * stride;
    block.resize(static_cast<std::size_t>(n) * stride);
    in.seekg(static_cast<std::streamoff>(at));
    in.read(reinterpret_cast<char*>(block.data()), static_cast<std::streamsize>(block.size()));
    if (!in || static_cast<std::size_t>(in.gcount()) != block.size()) {
      fail_at_offset(path, at, "read failed (the file changed since its header was read?)");
    }
    for (std::int64_t i = 0; i < n; ++i) {
      use(first + b + i, block.data() + static_cast<std::size_t>(i) * stride);
    }
  }
}

std::ifstream open(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open for reading");
  return in;
}

/// Rows of three fields of the vertex records of `ids` (or of begin .. end - 1 when ids is empty
/// and `range` is set).
RowMatrixX3d vertex_rows(const PlyTriangleReader::Layout& l, const RecordField (&field)[3],
                         std::span<const int> ids, std::int64_t begin, std::int64_t end,
                         bool range) {
  std::ifstream in = open(l.path);
  std::vector<unsigned char> block;
  RowMatrixX3d out(range ? end - begin : static_cast<Eigen::Index>(ids.size()), 3);
  const auto row = [&](Eigen::Index r, const unsigned char* rec) {
    for (int c = 0; c < 3; ++c)
      out(r, c) = load_as<double>(rec + field[c].offset, field[c].type, l.swap);
  };
  if (range) {
    for_each_record(in, l.path, l.vertex_offset, l.vertex_stride, begin, end - begin, block,
                    [&](std::int64_t v, const unsigned char* rec) { row(v - begin, rec); });
    return out;
  }
  for (const int v : ids) {
    if (v < 0 || v >= l.vertex_count) {
      throw InvalidInput("PlyTriangleReader: vertex " + std::to_string(v) + " is not in [0, " +
                         std::to_string(l.vertex_count) + ")");
    }
  }
  // Runs of ascending ids with small gaps, each run's records read as one span.
  const std::uint64_t max_gap = std::max<std::uint64_t>(1, kGapBytes / l.vertex_stride);
  const std::uint64_t max_span = std::max<std::uint64_t>(1, kBlockBytes / l.vertex_stride);
  std::size_t k = 0;
  while (k < ids.size()) {
    std::size_t j = k + 1;
    while (j < ids.size() && ids[j] >= ids[j - 1] &&
           static_cast<std::uint64_t>(ids[j] - ids[j - 1]) <= max_gap &&
           static_cast<std::uint64_t>(ids[j] - ids[k]) < max_span) {
      ++j;
    }
    const int first = ids[k];
    std::size_t next = k;
    for_each_record(in, l.path, l.vertex_offset, l.vertex_stride, first, ids[j - 1] - first + 1,
                    block, [&](std::int64_t v, const unsigned char* rec) {
                      while (next < j && ids[next] == v)
                        row(static_cast<Eigen::Index>(next++), rec);
                    });
    k = j;
  }
  return out;
}

}  // namespace

PlyTriangleReader::PlyTriangleReader(const std::filesystem::path& path)
    : layout_(read_layout(path)) {}

const std::filesystem::path& PlyTriangleReader::path() const { return layout_->path; }
std::int64_t PlyTriangleReader::vertex_count() const { return layout_->vertex_count; }
std::int64_t PlyTriangleReader::face_count() const { return layout_->face_count; }
bool PlyTriangleReader::has_normals() const { return layout_->has_normals; }

RowMatrixX3d PlyTriangleReader::positions(std::int64_t begin, std::int64_t end) const {
  check_range(begin, end, layout_->vertex_count, "vertices");
  return vertex_rows(*layout_, layout_->position, {}, begin, end, true);
}

RowMatrixX3d PlyTriangleReader::positions(std::span<const int> ids) const {
  return vertex_rows(*layout_, layout_->position, ids, 0, 0, false);
}

RowMatrixX3d PlyTriangleReader::normals(std::int64_t begin, std::int64_t end) const {
  if (!layout_->has_normals) throw InvalidInput(layout_->path.string() + ": has no normals");
  check_range(begin, end, layout_->vertex_count, "vertices");
  return vertex_rows(*layout_, layout_->normal, {}, begin, end, true);
}

RowMatrixX3d PlyTriangleReader::normals(std::span<const int> ids) const {
  if (!layout_->has_normals) throw InvalidInput(layout_->path.string() + ": has no normals");
  return vertex_rows(*layout_, layout_->normal, ids, 0, 0, false);
}

RowMatrixX3i PlyTriangleReader::faces(std::int64_t begin, std::int64_t end) const {
  const Layout& l = *layout_;
  check_range(begin, end, l.face_count, "faces");
  std::ifstream in = open(l.path);
  std::vector<unsigned char> block;
  RowMatrixX3i out(end - begin, 3);
  const std::size_t item = scalar_size(l.corners.type);
  for_each_record(
      in, l.path, l.face_offset, l.face_stride, begin, end - begin, block,
      [&](std::int64_t f, const unsigned char* rec) {
        const std::uint64_t at = l.face_offset + static_cast<std::uint64_t>(f) * l.face_stride;
        const auto n =
            load_as<std::int64_t>(rec + l.corner_count.offset, l.corner_count.type, l.swap);
        if (n != 3) {
          fail_at_offset(l.path, at,
                         "face " + std::to_string(f) + " has " + std::to_string(n) +
                             " corners: streaming reads triangle meshes only "
                             "(fixed-size face records)");
        }
        for (int c = 0; c < 3; ++c) {
          const auto v =
              load_as<std::int64_t>(rec + l.corners.offset + c * item, l.corners.type, l.swap);
          if (v < 0 || v >= l.vertex_count) {
            fail_at_offset(l.path, at,
                           io_detail::ply::bad_corner(l.face, static_cast<std::uint64_t>(f), v,
                                                      l.vertex_count));
          }
          out(f - begin, c) = static_cast<std::int32_t>(v);
        }
      });
  return out;
}

}  // namespace focal
