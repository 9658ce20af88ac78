#pragma once
/// \file mesh_check.h
/// What is wrong with a mesh, counted per kind of problem: the findings behind the one-line
/// `Warning:` summary of `focal curvature` / `focal focal-mesh` and their `--strict` option.
///
/// Nothing here repairs anything. The estimators accept every finding: vertices a problem
/// touches come out `undefined` with NaN fields where no estimate exists (see curvature.h), the
/// others are computed normally. Conventions (edges, degenerate faces, components, orientation)
/// are those of neighbourhood.h, orientation.h and vertex_normals.h, whose counts are reused.

#include <optional>
#include <string>

#include "focal/core/mesh.h"
#include "focal/mesh/prepared.h"

namespace focal {

/// Counts of the problems found in a mesh. The first group is about positions and faces, the
/// second about the given normals (all zero when none were given). Boundaries and several
/// components are normal for scans and are counted only for information: they are not problems.
struct MeshFindings {
  // Positions and faces.
  int non_finite_vertex_count = 0;       ///< vertices with a NaN or infinite coordinate
  int repeated_index_face_count = 0;     ///< faces such as (a, a, b)
  int degenerate_face_count = 0;         ///< other faces of numerically zero area (collinear or
                                         ///< coincident corners; the threshold is
                                         ///< vertex_normals.h's)
  int duplicate_face_count = 0;          ///< same vertex set as an earlier face (any order)
  int unreferenced_vertex_count = 0;     ///< vertices in no face (they get class `undefined`)
  int non_manifold_edge_count = 0;       ///< edges with three or more incident faces
  int non_manifold_vertex_count = 0;     ///< vertices whose faces form more than one fan
  int inconsistent_component_count = 0;  ///< components whose neighbouring faces disagree on
                                         ///< orientation along some edge
  int inward_component_count = 0;        ///< closed, consistent components with negative volume
  // Given normals.
  int non_finite_normal_count = 0;      ///< rows with a NaN or infinite component
  int zero_normal_count = 0;            ///< rows of length 0
  int non_unit_normal_count = 0;        ///< finite, non-zero rows whose length is not 1 within 1e-6
  int normals_against_faces_count = 0;  ///< vertices whose normal points against the
                                        ///< area-weighted normal of their faces (negative dot)
  int normals_compared_count = 0;       ///< vertices where both that normal and their faces' exist:
                                        ///< the base of normals_against_faces_count (not a problem)
  int inward_normal_component_count = 0;  ///< closed consistent components where most normals
                                          ///< point inside (against the outward face normals)
  // For information only.
  int boundary_edge_count = 0;  ///< edges with one incident face (holes, open borders)
  int component_count = 0;      ///< connected components of faces (sharing a vertex)

  /// True when any problem (not boundaries or components) was counted.
  [[nodiscard]] bool has_problems() const;
  /// The non-zero problem counts, comma-separated, e.g. "2 non-finite vertices, 1 duplicate
  /// face"; empty when there are none.
  [[nodiscard]] std::string summary() const;
};

/// Counts the problems of a mesh and of its normals when it has them. Linear time, parallel where
/// the reused functions are, and deterministic. Computed once per PreparedMesh (the estimate
/// pipeline, estimate.h, reads them again) on its kept vertex-face incidence.
[[nodiscard]] MeshFindings check_mesh(const PreparedMesh& mesh);

/// check_mesh of the arrays. \param V #V x 3 positions (NaN and infinities allowed). \param F
/// #F x 3 triangles. \param N #V x 3 normals as given, or std::nullopt when there are none.
/// \throw InvalidInput when F indexes outside V or N does not have #V rows.
[[nodiscard]] MeshFindings check_mesh(PositionsRef V, FacesRef F,
                                      std::optional<NormalsRef> N = std::nullopt);

}  // namespace focal
