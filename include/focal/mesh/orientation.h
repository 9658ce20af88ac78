#pragma once
/// \file orientation.h
/// Orientation of a mesh's faces: connected components with their closedness, consistency and
/// signed volume, outward and consistent reorientation.
///
/// Conventions (shared with neighbourhood.h): faces are counter-clockwise seen from outside; an
/// edge is a pair of distinct vertices of a common face, and its incident faces are the faces
/// having both as corners. A face with a repeated vertex index has no orientation along its edges.
///
/// Parallel on the current ExecutionScope's thread count (focal/core/execution.h); results do not
/// depend on it.

#include <vector>

#include "focal/core/mesh.h"
#include "focal/mesh/prepared.h"

namespace focal {

/// Orientation of one connected component (faces sharing a vertex are connected, so two closed
/// surfaces touching at one vertex form one component).
struct ComponentOrientation {
  int face_count = 0;
  int vertex_count = 0;        ///< vertices in the component's faces
  bool closed = false;         ///< every edge has exactly two incident faces
  bool consistent = false;     ///< every interior (two-face) edge is traversed in opposite
                               ///< directions; edges with one or 3+ faces are not checked
  double signed_volume = 0.0;  ///< divergence-theorem volume sum det(v0, v1, v2) / 6 about the
                               ///< component's vertex centroid; > 0 for outward closed surfaces
  bool inward = false;         ///< closed, consistent and signed_volume < 0
};

struct OrientationReport {
  Eigen::VectorXi face_component;  ///< #F component index of each face, numbered in order of
                                   ///< each component's first face
  std::vector<ComponentOrientation> components;
  [[nodiscard]] int inward_count() const;
};

/// Connected components of the faces and the orientation of each.
/// \throw InvalidInput when F indexes outside V.
[[nodiscard]] OrientationReport orientation_report(PositionsRef V, FacesRef F);

/// orientation_report of a prepared mesh, on its kept vertex-face incidence.
[[nodiscard]] OrientationReport orientation_report(const PreparedMesh& mesh);

/// Returns F with the faces of every inward (closed, consistent, negative-volume) component
/// reversed, so that vertex normals computed from it point outward. Other faces are unchanged.
/// \throw InvalidInput when `report` was not computed for a mesh with F's face count.
[[nodiscard]] RowMatrixX3i orient_outward(FacesRef F, const OrientationReport& report);

/// Faces after orient_consistently, and what could not be made consistent.
struct ConsistentFaces {
  RowMatrixX3i F;                  ///< #F x 3, the input with some faces reversed
  int flipped_face_count = 0;      ///< faces reversed
  int conflicting_edge_count = 0;  ///< interior edges still traversed the same way by both faces:
                                   ///< 0 unless a patch is non-orientable (a Moebius strip)
};

/// Reverses faces so that faces sharing an interior (two-face) edge traverse it in opposite
/// directions wherever possible. Works per patch (faces connected through interior edges, by
/// breadth-first search from each patch's lowest-index face) and keeps the orientation of the
/// majority of each patch's faces (on a tie, that of the lowest-index face), so a mostly correct
/// mesh changes little. Faces with a repeated index have no orientation and are left alone. Does
/// not decide inside from outside: follow with orientation_report and orient_outward for that.
/// Linear time (the search is serial).
/// \throw InvalidInput when vertex_count < 0 or F indexes outside [0, vertex_count).
[[nodiscard]] ConsistentFaces orient_consistently(int vertex_count, FacesRef F);

}  // namespace focal
