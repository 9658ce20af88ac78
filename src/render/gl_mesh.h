#pragma once
// Meshes on the GPU: float copies of the per-vertex arrays and the indices of the faces that can
// be drawn, in a vertex array object.

#include <vector>

#include "focal/core/mesh.h"
#include "render/gl_context.h"

namespace focal::render_detail {

/// Per-vertex attributes, 3 floats per vertex each (size: 1); an empty array is left out.
/// Locations: 0 position, 1 normal, 2 colour, 3 size (the radius of a point's splat).
struct VertexAttributes {
  std::vector<float> position;
  std::vector<float> normal;
  std::vector<float> colour;
  std::vector<float> size;
};

/// Row-major float copy of an n x 3 array.
[[nodiscard]] std::vector<float> to_floats(const Eigen::Ref<const RowMatrixX3d>& rows);

/// Corner indices (3 per face) of the faces whose corners all have finite positions and, when
/// N has rows, finite normals: the rest cannot be projected or shaded.
[[nodiscard]] std::vector<GLuint> drawable_faces(PositionsRef V, FacesRef F, NormalsRef N);

/// Uploads into a new vertex array object, left bound; returns the number of indices.
GLsizei upload_mesh(const VertexAttributes& attributes, const std::vector<GLuint>& indices);

}  // namespace focal::render_detail
