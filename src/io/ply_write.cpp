// PLY writing: binary little endian (the default) or ascii, positions and normals as doubles
// (floats with Precision::float32), per-vertex properties, triangles as
// `list uchar int vertex_indices`. The types, names and byte order shared with the reader are in
// io/ply.h.

#include <algorithm>
#include <cmath>
#include <memory>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "io/atomic_file.h"
#include "io/number_text.h"
#include "io/ply.h"

namespace focal {
namespace {

using io_detail::PlyColumn;
using io_detail::put_little_endian;
using io_detail::ply::scalar_name;
using io_detail::ply::scalar_of;
using io_detail::ply::scalar_size;

/// The header's name of a property of type t ("float", "double", "uchar", "int").
std::string_view ply_type_name(PropertyType t) { return scalar_name(scalar_of(t)); }

/// Bytes of one binary value of a property of type t.
std::size_t property_bytes(PropertyType t) { return scalar_size(scalar_of(t)); }

/// The type positions and normals are written as.
PropertyType real_type(Precision precision) {
  return precision == Precision::float32 ? PropertyType::float32 : PropertyType::float64;
}

bool valid_property_name(std::string_view name) {
  if (name.empty()) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return static_cast<unsigned char>(c) > ' ' && c != 127; });
}

/// Throws InvalidInput for anything the file could not represent faithfully.
void validate_for_ply(const std::filesystem::path& path, const Mesh& mesh,
                      std::span<const PlyColumn> columns, const PlyWriteOptions& options) {
  const std::string what = "write_ply: " + path.string();
  validate_mesh_arrays(mesh.V, mesh.F, mesh.N, what.c_str());
  std::vector<std::string_view> names = {"x", "y", "z"};
  if (mesh.has_normals()) names.insert(names.end(), {"nx", "ny", "nz"});
  for (const auto& column : columns) {
    const std::string name(column.name);
    if (!valid_property_name(name)) {
      throw InvalidInput(what + ": property name '" + name + "' is empty or contains blanks");
    }
    if (std::find(names.begin(), names.end(), column.name) != names.end()) {
      throw InvalidInput(what + ": property name '" + name + "' is used twice");
    }
    names.push_back(column.name);
    if (column.size != mesh.V.rows()) {
      throw InvalidInput(what + ": property '" + name + "' has " + std::to_string(column.size) +
                         " values but the mesh has " + std::to_string(mesh.V.rows()) + " vertices");
    }
    // uint8 codes fit both integer types; only doubles need checking.
    const bool is_int = column.type == PropertyType::uint8 || column.type == PropertyType::int32;
    const double lo = column.type == PropertyType::uint8 ? 0.0 : -2147483648.0;
    const double hi = column.type == PropertyType::uint8 ? 255.0 : 2147483647.0;
    for (Eigen::Index i = 0; is_int && column.f64 != nullptr && i < column.size; ++i) {
      const double v = column.value(i);
      if (!(v >= lo && v <= hi && v == std::floor(v))) {
        throw InvalidInput(what + ": property '" + name + "' value " + std::to_string(v) +
                           " at vertex " + std::to_string(i) + " is not representable as " +
                           std::string(ply_type_name(column.type)));
      }
    }
  }
  for (const auto& comment : options.comments) {
    if (comment.find_first_of("\r\n") != std::string::npos) {
      throw InvalidInput(what + ": a comment contains a line break");
    }
  }
}

std::string ply_header(const Mesh& mesh, std::span<const PlyColumn> columns,
                       const PlyWriteOptions& options) {
  std::string h = "ply\nformat ";
  h += options.binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
  for (const auto& comment : options.comments) h += "comment " + comment + "\n";
  h += "element vertex " + std::to_string(mesh.V.rows()) + "\n";
  const auto property = [&h](std::string_view type, std::string_view name) {
    h += "property ";
    h += type;
    h += ' ';
    h += name;
    h += '\n';
  };
  const std::string_view real = ply_type_name(real_type(options.precision));
  for (const char* name : {"x", "y", "z"}) property(real, name);
  if (mesh.has_normals()) {
    for (const char* name : {"nx", "ny", "nz"}) property(real, name);
  }
  for (const auto& column : columns) property(ply_type_name(column.type), column.name);
  h += "element face " + std::to_string(mesh.F.rows()) + "\n";
  h += "property list uchar int vertex_indices\nend_header\n";
  return h;
}

void append_property_ascii(std::string& out, PropertyType t, double v) {
  switch (t) {
    case PropertyType::float32:
      io_detail::append_number(out, static_cast<float>(v));
      break;
    case PropertyType::float64:
      io_detail::append_number(out, v);
      break;
    case PropertyType::uint8:
    case PropertyType::int32:
      io_detail::append_number(out, static_cast<std::int64_t>(v));
      break;
  }
}

void write_ply_body_ascii(io_detail::OutputSink& sink, const Mesh& mesh,
                          std::span<const PlyColumn> columns, Precision precision, int threads) {
  const bool normals = mesh.has_normals();
  io_detail::write_lines(sink, mesh.V.rows(), threads, [&](std::string& out, std::int64_t i) {
    for (int c = 0; c < (normals ? 6 : 3); ++c) {
      if (c > 0) out += ' ';
      io_detail::append_real(out, c < 3 ? mesh.V(i, c) : mesh.N(i, c - 3), precision);
    }
    for (const auto& column : columns) {
      out += ' ';
      append_property_ascii(out, column.type, column.value(i));
    }
    out += '\n';
  });
  io_detail::write_lines(sink, mesh.F.rows(), threads, [&](std::string& out, std::int64_t f) {
    io_detail::append_ascii_triangle(out, mesh.F, f);
  });
}

/// Writes `count` fixed-size records of `record` bytes in batches of about 8 MiB, each filled in
/// parallel blocks by put(begin, end, out) (records [begin, end) stored from `out` on) and then
/// written. Every record has its own place in the batch, so the bytes do not depend on the
/// thread count.
template <class Put>
void write_fixed_records(io_detail::OutputSink& sink, std::int64_t count, std::size_t record,
                         int threads, const Put& put) {
  if (count == 0) return;
  constexpr std::int64_t kBlock = 1 << 12;
  const std::int64_t per_batch =
      std::max<std::int64_t>(1,
                             static_cast<std::int64_t>((std::size_t{8} << 20) / record / kBlock)) *
      kBlock;
  const std::int64_t batch = std::min(count, per_batch);
  const std::unique_ptr<char[]> buffer(new char[static_cast<std::size_t>(batch) * record]);
  for (std::int64_t first = 0; first < count; first += batch) {
    const std::int64_t n = std::min(batch, count - first);
    detail::parallel_for_blocks(n, kBlock, threads, [&](std::int64_t begin, std::int64_t end) {
      put(first + begin, first + end, buffer.get() + static_cast<std::size_t>(begin) * record);
    });
    sink.write(buffer.get(), static_cast<std::size_t>(n) * record);
  }
}

/// Stores x y z (and nx ny nz) of records [begin, end) as T at the start of each record of `out`.
template <class T>
void put_positions(char* out, std::size_t record, std::int64_t begin, std::int64_t end,
                   const Mesh& mesh, bool normals) {
  for (std::int64_t i = begin; i < end; ++i) {
    char* p = out + static_cast<std::size_t>(i - begin) * record;
    for (int c = 0; c < 3; ++c) p = put_little_endian(p, static_cast<T>(mesh.V(i, c)));
    if (normals) {
      for (int c = 0; c < 3; ++c) p = put_little_endian(p, static_cast<T>(mesh.N(i, c)));
    }
  }
}

/// Stores column values for records [begin, end) at `offset` in each record of `out`.
template <class T, class Source>
void put_column(char* out, std::size_t record, std::int64_t begin, std::int64_t end,
                const Source* values, Eigen::Index stride) {
  for (std::int64_t i = begin; i < end; ++i) {
    put_little_endian(out + static_cast<std::size_t>(i - begin) * record,
                      static_cast<T>(static_cast<double>(values[i * stride])));
  }
}

/// put_column() with the file type of `type`.
template <class Source>
void put_column_as(PropertyType type, char* out, std::size_t record, std::int64_t begin,
                   std::int64_t end, const Source* values, Eigen::Index stride) {
  switch (type) {
    case PropertyType::float32:
      put_column<float>(out, record, begin, end, values, stride);
      break;
    case PropertyType::float64:
      put_column<double>(out, record, begin, end, values, stride);
      break;
    case PropertyType::uint8:
      put_column<std::uint8_t>(out, record, begin, end, values, stride);
      break;
    case PropertyType::int32:
      put_column<std::int32_t>(out, record, begin, end, values, stride);
      break;
  }
}

void write_ply_body_binary(io_detail::OutputSink& sink, const Mesh& mesh,
                           std::span<const PlyColumn> columns, const PlyWriteOptions& options) {
  const bool normals = mesh.has_normals();
  const bool f32 = options.precision == Precision::float32;
  const std::size_t positions = (normals ? 6 : 3) * property_bytes(real_type(options.precision));
  std::size_t record = positions;
  for (const auto& column : columns) record += property_bytes(column.type);
  // Column by column within a block, so that each type is dispatched once per block.
  write_fixed_records(sink, mesh.V.rows(), record, 0,
                      [&](std::int64_t begin, std::int64_t end, char* out) {
                        if (f32) {
                          put_positions<float>(out, record, begin, end, mesh, normals);
                        } else {
                          put_positions<double>(out, record, begin, end, mesh, normals);
                        }
                        std::size_t offset = positions;
                        for (const auto& column : columns) {
                          char* at = out + offset;
                          const Eigen::Index s = column.stride;
                          if (column.f64 != nullptr) {
                            put_column_as(column.type, at, record, begin, end, column.f64, s);
                          } else {
                            put_column_as(column.type, at, record, begin, end, column.u8, s);
                          }
                          offset += property_bytes(column.type);
                        }
                      });
  write_fixed_records(sink, mesh.F.rows(), 1 + 3 * sizeof(std::int32_t), 0,
                      [&](std::int64_t begin, std::int64_t end, char* out) {
                        char* p = out;
                        for (std::int64_t f = begin; f < end; ++f) {
                          *p++ = static_cast<char>(3);
                          for (int c = 0; c < 3; ++c) p = put_little_endian(p, mesh.F(f, c));
                        }
                      });
}

}  // namespace

namespace io_detail {

void write_ply_columns(const std::filesystem::path& path, const Mesh& mesh,
                       std::span<const PlyColumn> columns, const PlyWriteOptions& options) {
  validate_for_ply(path, mesh, columns, options);
  // float32 outputs: the double columns are declared `float` and converted as they are written
  // (put_column_as, append_property_ascii), by the same code as the columns that are always float.
  std::vector<PlyColumn> file_columns(columns.begin(), columns.end());
  if (options.precision == Precision::float32) {
    for (auto& column : file_columns) {
      if (column.type == PropertyType::float64) column.type = PropertyType::float32;
    }
  }
  write_atomically(path, [&](OutputSink& sink) {
    sink.buffer() += ply_header(mesh, file_columns, options);
    if (options.binary) {
      write_ply_body_binary(sink, mesh, file_columns, options);
    } else {
      write_ply_body_ascii(sink, mesh, file_columns, options.precision, 0);
    }
  });
}

}  // namespace io_detail

void write_ply(const std::filesystem::path& path, const Mesh& mesh,
               std::span<const VertexProperty> properties, const PlyWriteOptions& options) {
  std::vector<PlyColumn> columns;
  columns.reserve(properties.size());
  for (const auto& prop : properties) {
    columns.push_back({prop.name, prop.type, prop.values.data(), nullptr, prop.values.size(), 1});
  }
  io_detail::write_ply_columns(path, mesh, columns, options);
}

}  // namespace focal
