#pragma once
/// \file ply.h
/// PLY internals shared by the reader (ply_read.cpp), the writer (ply_write.cpp) and the field
/// writers (fields_io.cpp): the scalar types and their names, byte order, and the writer on
/// columns read in place.
/// Format reference: Greg Turk, "The PLY Polygon File Format" (1994), and the type aliases
/// (int8..float64) added by later writers such as VTK and rply.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string_view>

#include "focal/core/mesh.h"
#include "focal/io/mesh_io.h"
#include "io/bytes.h"

namespace focal::io_detail {

namespace ply {

/// The scalar types of PLY properties (and of list counts and items).
enum class Scalar : std::uint8_t {
  int8,
  uint8,
  int16,
  uint16,
  int32,
  uint32,
  int64,
  uint64,
  float32,
  float64
};

/// Bytes of one binary value of type t.
constexpr std::size_t scalar_size(Scalar t) {
  switch (t) {
    case Scalar::int8:
    case Scalar::uint8:
      return 1;
    case Scalar::int16:
    case Scalar::uint16:
      return 2;
    case Scalar::int32:
    case Scalar::uint32:
    case Scalar::float32:
      return 4;
    case Scalar::int64:
    case Scalar::uint64:
    case Scalar::float64:
      return 8;
  }
  return 0;
}

constexpr bool is_integer(Scalar t) { return t != Scalar::float32 && t != Scalar::float64; }

/// Every type name a header may use: Turk's names first (the ones focal writes), then the sized
/// aliases, then the 64-bit integers that meshio and numpy-based writers add.
struct ScalarName {
  std::string_view name;
  Scalar type;
};
inline constexpr ScalarName kScalarNames[] = {
    {"char", Scalar::int8},       {"uchar", Scalar::uint8},    {"short", Scalar::int16},
    {"ushort", Scalar::uint16},   {"int", Scalar::int32},      {"uint", Scalar::uint32},
    {"float", Scalar::float32},   {"double", Scalar::float64}, {"int8", Scalar::int8},
    {"uint8", Scalar::uint8},     {"int16", Scalar::int16},    {"uint16", Scalar::uint16},
    {"int32", Scalar::int32},     {"uint32", Scalar::uint32},  {"float32", Scalar::float32},
    {"float64", Scalar::float64}, {"int64", Scalar::int64},    {"uint64", Scalar::uint64},
};

/// The type a header names `name`; false for an unknown name.
inline bool parse_scalar_type(std::string_view name, Scalar& t) {
  for (const auto& alias : kScalarNames) {
    if (alias.name == name) {
      t = alias.type;
      return true;
    }
  }
  return false;
}

/// Turk's name of type t ("uchar", "int", "float", "double", ...), as focal writes it.
constexpr std::string_view scalar_name(Scalar t) {
  for (const auto& alias : kScalarNames) {
    if (alias.type == t) return alias.name;
  }
  return "double";
}

/// The PLY type a VertexProperty of type t is stored as.
constexpr Scalar scalar_of(PropertyType t) {
  switch (t) {
    case PropertyType::float32:
      return Scalar::float32;
    case PropertyType::float64:
      return Scalar::float64;
    case PropertyType::uint8:
      return Scalar::uint8;
    case PropertyType::int32:
      return Scalar::int32;
  }
  return Scalar::float64;
}

}  // namespace ply

/// One per-vertex column for write_ply_columns(): value i is f64[i * stride] or u8[i * stride],
/// read in place, so that callers holding the values in other arrays (a matrix column, a uint8
/// code vector) need not copy them into a VertexProperty first.
struct PlyColumn {
  std::string_view name;
  PropertyType type = PropertyType::float32;
  const double* f64 = nullptr;       ///< the values when they are doubles, else null
  const std::uint8_t* u8 = nullptr;  ///< the values when they are uint8 codes, else null
  Eigen::Index size = 0;             ///< number of values
  Eigen::Index stride = 1;           ///< distance between consecutive values, in elements

  [[nodiscard]] double value(Eigen::Index i) const {
    return f64 != nullptr ? f64[i * stride] : static_cast<double>(u8[i * stride]);
  }
};

/// write_ply() on columns: same file, same validation and exceptions.
void write_ply_columns(const std::filesystem::path& path, const Mesh& mesh,
                       std::span<const PlyColumn> columns, const PlyWriteOptions& options);

}  // namespace focal::io_detail
