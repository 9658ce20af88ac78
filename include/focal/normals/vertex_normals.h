#pragma once
/// \file vertex_normals.h
/// Vertex normals estimated from the faces around each vertex (area, angle or Max weights), and
/// how given normals compare with them.
///
/// Conventions (shared with neighbourhood.h and orientation.h): faces are counter-clockwise seen
/// from outside. A face is degenerate when it repeats an index or has numerically zero area:
/// |(b - a) x (c - a)| <= 1e-14 L^2 with L its longest edge (scale invariant).
///
/// Parallel on the current ExecutionScope's thread count (focal/core/execution.h); results do not
/// depend on it.

#include "focal/core/mesh.h"
#include "focal/mesh/prepared.h"

namespace focal {

/// How face normals are weighted into a vertex normal.
enum class NormalWeighting {
  area,   ///< by triangle area (sum of un-normalised face normals)
  angle,  ///< by the triangle's interior angle at the vertex (Thuermer & Wuethrich 1998)
  max,    ///< Max (1999): sin(angle) / (|e1| |e2|), exact for vertices on a sphere
};

/// Unit vertex normals, #V x 3, oriented like the faces (counter-clockwise = outward).
/// At corner P of a face with counter-clockwise successors Q, R, let e1 = Q - P, e2 = R - P and
/// n = e1 x e2. The face contributes n (area), angle(e1, e2) n / |n| (angle) or
/// n / (|e1|^2 |e2|^2) (max; N. Max, "Weights for computing vertex normals from facet normals",
/// J. Graphics Tools 4(2), 1999: exact when P and its neighbours lie on a sphere).
/// Degenerate faces contribute nothing. Faces are summed in ascending order per vertex, so the
/// result does not depend on the thread count.
/// Vertices in no face, or whose sum vanishes (|sum| <= 1e-12 * sum of |contribution|, e.g. two
/// opposite faces), get a NaN row (never a silent zero).
/// \throw InvalidInput when F indexes outside V.
[[nodiscard]] RowMatrixX3d vertex_normals(PositionsRef V, FacesRef F,
                                          NormalWeighting weighting = NormalWeighting::angle);

/// vertex_normals of a prepared mesh, on its kept vertex-face incidence.
[[nodiscard]] RowMatrixX3d vertex_normals(const PreparedMesh& mesh,
                                          NormalWeighting weighting = NormalWeighting::angle);

/// Fraction of vertices (in at least one face, with finite N) whose given normal points against
/// the area-weighted face normal (negative dot product): near 1 means the normals are inward.
/// Vertices whose area-weighted normal vanishes (see vertex_normals) are not counted. NaN when no
/// vertex qualifies.
/// \throw InvalidInput when F indexes outside V or N does not have #V rows.
[[nodiscard]] double fraction_against_faces(PositionsRef V, FacesRef F, NormalsRef N);

}  // namespace focal
