#pragma once
// Triangulations of a parameter domain: regular grids and discs, and irregular Poisson-disk
// samples with Delaunay-quality triangles (surfaces.h describes both).

#include <cstdint>
#include <vector>

#include "surfaces/surface_model.h"

namespace focal::detail {

/// Vertices by parameters and outward (counter-clockwise) triangles.
struct Triangulated {
  std::vector<Eigen::Vector2d> uv;
  std::vector<Face> faces;
};

/// Area and shape of a domain, by the midpoint rule on a fixed grid.
struct DomainStats {
  double area = 0.0;
  double max_area_element = 0.0;  ///< max |X_u x X_v| over the grid
  /// Area-weighted mean of log(|X_u| (u_max - u_min) / (|X_v| (v_max - v_min))): the ratio of
  /// u to v grid intervals that makes cells square in space.
  double log_aspect = 0.0;
  double max_curvature = 0.0;  ///< max(|k1|, |k2|) over the grid
};

bool in_domain(const ParameterDomain& d, const Eigen::Vector2d& uv);
DomainStats domain_stats(const Parametrisation& s, const ParameterDomain& d);

/// Fraction of the plane covered by random sequential adsorption at jamming (0.547) in terms
/// of the exclusion radius r: n = kPacking * area / r^2, tuned for the finite candidate pool.
constexpr double kPacking = 0.62;
/// Largest sample spacing times the largest |curvature|. Coarser meshes cannot follow the
/// surface: a face then spans so much of the normal's turning that it need not agree with the
/// exact normals at its corners. At this bound the worst face . corner normal measured over 30
/// seeds of every surface was 0.33 (torus) and 0.36 (helix tube), 0.5 or more elsewhere.
constexpr double kMaxSpacingCurvature = 0.8;
constexpr int kMaxTarget = 100'000'000;

/// target, raised where the surface is too curved for that few vertices (see above).
int effective_target(const DomainStats& stats, int target);

/// A (u, v) grid: rows of constant u, periodic directions wrapped, pole rows collapsed.
Triangulated regular_grid(const ParameterDomain& d, int target, double log_aspect);

/// Concentric rings of 6k vertices, k = 0..m, stitched ring to ring in angular order: the
/// hexagonal triangulation of a disc bent onto its circle.
Triangulated regular_disc(double radius, int target);

/// Poisson-disk samples of about `target` vertices, triangulated in a planar chart and improved
/// by edge flips in space; `grading` (>= 1) is the ratio of the density at u_max to u_min.
Triangulated irregular_triangulation(const Parametrisation& s, const ParameterDomain& d,
                                     const DomainStats& stats, int target, std::uint64_t seed,
                                     double grading = 1.0);

}  // namespace focal::detail
