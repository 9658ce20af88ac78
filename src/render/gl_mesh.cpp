#include "render/gl_mesh.h"

namespace focal::render_detail {
namespace {

bool finite_row(const Eigen::Ref<const RowMatrixX3d>& rows, Eigen::Index i) {
  return rows.row(i).allFinite();
}

void upload_attribute(GLuint location, const std::vector<float>& values, GLint components = 3) {
  if (values.empty()) return;
  GLuint buffer = 0;
  glGenBuffers(1, &buffer);
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(values.size() * sizeof(float)),
               values.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(location);
  glVertexAttribPointer(location, components, GL_FLOAT, GL_FALSE, 0, nullptr);
}

}  // namespace

std::vector<float> to_floats(const Eigen::Ref<const RowMatrixX3d>& rows) {
  std::vector<float> out(static_cast<std::size_t>(rows.rows()) * 3);
  for (Eigen::Index i = 0; i < rows.rows(); ++i) {
    for (int c = 0; c < 3; ++c)
      out[3 * static_cast<std::size_t>(i) + c] = static_cast<float>(rows(i, c));
  }
  return out;
}

std::vector<GLuint> drawable_faces(PositionsRef V, FacesRef F, NormalsRef N) {
  std::vector<char> ok(static_cast<std::size_t>(V.rows()));
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    ok[i] = finite_row(V, i) && (N.rows() == 0 || finite_row(N, i));
  }
  std::vector<GLuint> indices;
  indices.reserve(static_cast<std::size_t>(F.rows()) * 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if (!ok[F(f, 0)] || !ok[F(f, 1)] || !ok[F(f, 2)]) continue;
    for (int c = 0; c < 3; ++c) indices.push_back(static_cast<GLuint>(F(f, c)));
  }
  return indices;
}

GLsizei upload_mesh(const VertexAttributes& attributes, const std::vector<GLuint>& indices) {
  GLuint vertex_array = 0;
  glGenVertexArrays(1, &vertex_array);
  glBindVertexArray(vertex_array);
  upload_attribute(0, attributes.position);
  upload_attribute(1, attributes.normal);
  upload_attribute(2, attributes.colour);
  upload_attribute(3, attributes.size, 1);
  GLuint index_buffer = 0;
  glGenBuffers(1, &index_buffer);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(GLuint)),
               indices.data(), GL_STATIC_DRAW);
  require_no_gl_error("uploading the mesh");
  return static_cast<GLsizei>(indices.size());
}

}  // namespace focal::render_detail
