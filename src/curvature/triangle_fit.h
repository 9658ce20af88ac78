#pragma once
// Internal: the per-triangle estimator of triangle_curvature.cpp, for estimate_curvature
// (Method::triangle) and the tests.

#include <vector>

#include "core/simd_lanes.h"
#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/triangle_curvature.h"
#include "focal/mesh/prepared.h"

namespace focal::detail {

/// focal::triangle_curvature with the faces solved by the lane kernel compiled for `isa`
/// (tests compare the instruction sets).
TriangleCurvatureResult triangle_curvature(const PreparedMesh& mesh,
                                           const CurvatureOptions& options,
                                           const TriangleFields& fields, SimdIsa isa);

/// The same on arrays.
TriangleCurvatureResult triangle_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options,
                                           const TriangleFields& fields, SimdIsa isa);

/// estimate_curvature with Method::triangle: the faces' shape operators averaged to the vertices
/// (paper 5.1), on a mesh with normals.
CurvatureResult vertex_curvature_from_triangles(const PreparedMesh& mesh,
                                                const CurvatureOptions& options);

/// vertex_curvature_from_triangles written into `r` (a result of the mesh's vertices) where
/// `replace[i]` is set and the triangles give an estimate at vertex i; the other rows are left as
/// they are. The same rows as copying from vertex_curvature_from_triangles' result, without
/// a second result of the whole mesh.
void replace_with_triangles(const PreparedMesh& mesh, const CurvatureOptions& options,
                            const std::vector<char>& replace, CurvatureResult& r);

}  // namespace focal::detail
