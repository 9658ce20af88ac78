#pragma once
/// \file evaluation.h
/// Error metrics of curvature estimates against analytic truth, as used by `focal eval`.

#include <filesystem>
#include <string>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"
#include "focal/surfaces/surfaces.h"

namespace focal {

/// Errors over one set of vertices. Relative errors are RMS(error) / RMS(truth); where the truth
/// is (near) zero the relative value is NaN and the absolute RMS says it.
struct ErrorMetrics {
  int vertices = 0;   ///< vertices measured
  int undefined = 0;  ///< of which the estimate was undefined or not finite
  double relative_H = 0, relative_K = 0, relative_k1 = 0, relative_k2 = 0;
  double rms_H = 0, rms_K = 0, rms_k1 = 0, rms_k2 = 0;
  double median_angle_d1 = 0;  ///< degrees, lines (mod 180), at non-umbilic vertices
  double mean_angle_d1 = 0;
  double variance_H = 0;  ///< of the estimate (the paper's Fig. 7 smoothness figure)
};

/// Interior vertices (more than `boundary_rings` rings from a boundary) and the rest, measured
/// separately. Undefined vertices are counted, and left out of the error sums.
struct Evaluation {
  ErrorMetrics interior;
  ErrorMetrics near_boundary;
};

/// Compares an estimate with the truth of an analytic surface. A vertex counts as umbilic for the
/// direction error when k1 - k2 <= 0.2 max |k| over the surface. Crease vertices
/// (AnalyticSurface::crease) are in neither set: their curvature does not exist.
[[nodiscard]] Evaluation evaluate(const AnalyticSurface& truth, const CurvatureResult& estimate,
                                  int boundary_rings = 2);

/// The errors over the vertices flagged 1 in `scored` (#V flags), crease vertices left out.
/// \throw InvalidInput when `scored` or the estimate has not #V entries.
[[nodiscard]] ErrorMetrics evaluate_at(const AnalyticSurface& truth,
                                       const CurvatureResult& estimate, const VectorXu8& scored);

/// #V flags, 1 for the vertices whose ring distance to the nearest boundary vertex lies in
/// [first_ring, last_ring] (0 is the boundary itself); all 0 on closed meshes.
/// \throw InvalidInput when F indexes outside [0, vertex_count) or the rings are not
/// 0 <= first_ring <= last_ring.
[[nodiscard]] VectorXu8 boundary_band_mask(int vertex_count, FacesRef F, int first_ring,
                                           int last_ring);

/// #V flags, 1 for the vertices evaluate() counts as interior (more than `boundary_rings` rings
/// from a boundary vertex), 0 for the others.
/// \throw InvalidInput when F indexes outside [0, vertex_count) or boundary_rings < 0.
[[nodiscard]] VectorXu8 interior_mask(int vertex_count, FacesRef F, int boundary_rings = 2);

/// Column names of the truth CSV written by export_case, in file order:
/// k1,k2,H,K,d1x,d1y,d1z,d2x,d2y,d2z,interior.
[[nodiscard]] const std::vector<std::string>& truth_field_names();

/// Writes one evaluation case for external tools, so that they measure the same vertices with the
/// same metrics: `mesh_path` gets the mesh exactly as the estimators see it (binary PLY, x y z and
/// the file normals nx ny nz as doubles, so both round-trip bit for bit), `truth_path` one CSV row
/// per vertex in the same order with the exact truth and the interior_mask flag.
/// \throw InvalidInput for inconsistent arrays; IoError naming the path on write failure.
void export_case(const std::filesystem::path& mesh_path, const std::filesystem::path& truth_path,
                 const AnalyticSurface& surface, int boundary_rings = 2);

/// export_case with the vertices to measure given as #V flags (written to the `interior` column;
/// crease vertices are written 0), for cases scored elsewhere than the interior.
void export_case(const std::filesystem::path& mesh_path, const std::filesystem::path& truth_path,
                 const AnalyticSurface& surface, const VectorXu8& scored);

/// How smooth a scalar field (mean curvature) is on a mesh without truth: the paper's Fig. 7
/// compares range and variance of H on scanned meshes. Values are made scale-free by multiplying
/// H by the mesh's mean edge length h, so meshes in different units compare. Vertices whose H is
/// NaN or infinite are counted as undefined and left out; so are edges with such an end.
/// |H h| at or below this counts as zero (no sign) for FieldSmoothness::sign_changes.
inline constexpr double kSignZero = 1e-9;

struct FieldSmoothness {
  int vertices = 0;
  int undefined = 0;
  double edge_length = 0;   ///< h, the mean edge length (focal::mean_edge_length)
  double min = 0, max = 0;  ///< of H h over the defined vertices
  double percentile_1 = 0, percentile_99 = 0;  ///< of H h, linear interpolation (numpy's default)
  double variance = 0;   ///< population variance of H h (divided by the count, numpy's var)
  int edges = 0;         ///< undirected edges with both ends defined
  int sign_changes = 0;  ///< of those, edges whose ends have H h of opposite signs, each
                         ///< beyond kSignZero in magnitude
  double sign_change_fraction = 0;  ///< sign_changes / edges; NaN without edges
};

/// \throw InvalidInput when H has not #V entries or F indexes outside V. All statistics are NaN
/// (counts 0) when no vertex is defined.
[[nodiscard]] FieldSmoothness field_smoothness(PositionsRef V, FacesRef F,
                                               const Eigen::VectorXd& H);

}  // namespace focal
