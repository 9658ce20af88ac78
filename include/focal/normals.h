#pragma once
/// \file normals.h
/// Vertex normals estimated from faces, and orientation checks per connected component.

#include <vector>

#include "focal/mesh.h"

namespace focal {

/// How face normals are weighted into a vertex normal.
enum class NormalWeighting {
  area,   ///< by triangle area (sum of un-normalised face normals)
  angle,  ///< by the triangle's interior angle at the vertex (Thuermer & Wuethrich 1998)
  max,    ///< Max (1999): sin(angle) / (|e1| |e2|), exact for vertices on a sphere
};

/// Unit vertex normals, #V x 3, oriented like the faces (counter-clockwise = outward).
/// Vertices in no face, or whose weighted sum vanishes, get a NaN row (never a silent zero).
/// \throw InvalidInput when F indexes outside V.
[[nodiscard]] RowMatrixX3d vertex_normals(PositionsRef V, FacesRef F,
                                          NormalWeighting weighting = NormalWeighting::angle);

/// Orientation of one connected component (vertices connected through faces).
struct ComponentOrientation {
  int face_count = 0;
  int vertex_count = 0;
  bool closed = false;         ///< every edge has exactly two incident faces
  bool consistent = false;     ///< every interior edge is traversed in opposite directions
  double signed_volume = 0.0;  ///< divergence-theorem volume; > 0 for outward closed surfaces
  bool inward = false;         ///< closed, consistent and signed_volume < 0
};

struct OrientationReport {
  Eigen::VectorXi face_component;  ///< #F component index of each face
  std::vector<ComponentOrientation> components;
  [[nodiscard]] int inward_count() const;
};

/// Connected components of the faces and the orientation of each.
[[nodiscard]] OrientationReport orientation_report(PositionsRef V, FacesRef F);

/// Returns F with the faces of every inward (closed, consistent, negative-volume) component
/// reversed, so that vertex normals computed from it point outward.
[[nodiscard]] RowMatrixX3i orient_outward(FacesRef F, const OrientationReport& report);

/// Fraction of vertices (in at least one face, with finite N) whose given normal points against
/// the area-weighted face normal (negative dot product): near 1 means the normals are inward.
[[nodiscard]] double fraction_against_faces(PositionsRef V, FacesRef F, NormalsRef N);

}  // namespace focal
