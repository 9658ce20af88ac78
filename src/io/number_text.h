#pragma once
/// \file number_text.h
/// Numbers written as the shortest text that reads back to the same value, and the vertex and
/// triangle lines of the text writers (OFF, ascii PLY, point-cloud text).

#include <cstdint>
#include <string>

#include "focal/core/mesh.h"
#include "focal/io/mesh_io.h"

namespace focal::io_detail {

/// Appends the shortest text that reads back to exactly `value`; NaN as `nan`, infinities as
/// `inf` / `-inf`.
void append_number(std::string& out, double value);
void append_number(std::string& out, float value);
void append_number(std::string& out, std::int64_t value);

/// append_number of `value`, or of static_cast<float>(value) with Precision::float32: the one
/// place where the text writers convert to float32 outputs.
inline void append_real(std::string& out, double value, Precision precision) {
  if (precision == Precision::float32) {
    append_number(out, static_cast<float>(value));
  } else {
    append_number(out, value);
  }
}

/// "3 a b c\n": one triangle as OFF and ascii PLY write it.
inline void append_ascii_triangle(std::string& out, const Eigen::Ref<const RowMatrixX3i>& F,
                                  Eigen::Index f) {
  out += '3';
  for (int c = 0; c < 3; ++c) {
    out += ' ';
    append_number(out, static_cast<std::int64_t>(F(f, c)));
  }
  out += '\n';
}

/// "x y z[ nx ny nz]\n": vertex i as OFF and point-cloud text write it (normals when `normals`).
inline void append_vertex_line(std::string& out, const Mesh& mesh, Eigen::Index i, bool normals,
                               Precision precision) {
  for (int c = 0; c < 3; ++c) {
    if (c > 0) out += ' ';
    append_real(out, mesh.V(i, c), precision);
  }
  for (int c = 0; normals && c < 3; ++c) {
    out += ' ';
    append_real(out, mesh.N(i, c), precision);
  }
  out += '\n';
}

}  // namespace focal::io_detail
