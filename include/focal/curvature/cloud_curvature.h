#pragma once
/// \file cloud_curvature.h
/// Curvature of point clouds (positions, normals optional) by focal surfaces: the paper's
/// estimator "uses both vertex position and normals and does not require connectivity
/// constraints" (Yu et al. 2007, section 6). Every point's neighbours (its k nearest, or those
/// within a radius: points/neighbours.h) give their normal rays in the point's tangent frame
/// (paper 4.1), and the two-slit fit (paper 5, closed form or Levenberg-Marquardt) gives k1, k2,
/// d1, d2, H, K, the residual and the class, exactly as for a mesh vertex's ring: the same fit
/// code runs on both.
///
/// The default (k = 0, radius = 0) adapts to the cloud, as the recommended estimator does on
/// meshes (docs/POINTS.md, where the thresholds were measured):
///  1. jet normals (cloud_normals: PCA, oriented by a minimum spanning tree or towards a
///     viewpoint, then cubic jets) over the 16 nearest neighbours, and the position noise:
///     the median jet residual over the mean spacing;
///  2. noisy positions (noise > 0.03; measured on the 8 analytic clouds at 3000 and 5000 points:
///     clean <= 0.0115, 10% noise 0.074-0.083): the fit and quadratic jet normals over
///     4 x 16 = 64 neighbours instead;
///  3. the cloud's own normals are used when their median angle to the jet normals is at most
///     2.5 times the noise (measured ratio: exact normals 0.49-0.62, exact normals on 10% noisy
///     positions 0.74-0.79, normal noise 0.05: 3.4 and more), else the jet normals turned to
///     their side; on clean positions (16 neighbours) each point's jet normal gives way to Max's
///     normal over its fan in its local triangulation (step 5's) where the two-slit residual of
///     Max's normals is below half the jets' (the mesh default's choice; exact on a sphere);
///  4. the two-slit fit, repeated without the rays far off it where there are such (the mesh
///     default's robust fit, curvature/robust_fit.h; clean fits keep every ray);
///  5. on clean positions (16 neighbours) where no point was flagged as an outlier, the mesh
///     default's corrected step on a local triangulation of each point (the Delaunay
///     triangulation of it and its neighbours projected onto its tangent plane): LRTC20's
///     corrected curvature measures of the normals over a ball of one local edge length,
///     wherever the fit is not exact (measured in docs/POINTS.md: the H error of the analytic
///     clean clouds 2-4x lower).
/// Before all of it (also with k or radius given), statistical outliers (outlier_points over the
/// 16 nearest, CloudOptions::outlier_ratio), then points off their neighbours' surface
/// (off_surface_points over the 16 nearest of the rest, CloudOptions::off_surface_ratio) are left
/// out as non-finite points are: they get no neighbours, are in no list, and are `undefined`.
/// With k or radius given: the fit over those neighbours, of the cloud's own normals (made unit;
/// zero or non-finite rows make their point `undefined`), else of cloud_normals over them.
///
/// Conventions as curvature.h: outward normals, a sphere of radius r has k1 = k2 = +1/r; the
/// classes' zero tolerance is relative to the cloud's mean spacing (mean_spacing) as it is to
/// the mean edge length of a mesh. Deterministic for any thread count.
///
/// estimate_cloud_curvature and estimate_cloud_normals run the default, and the k nearest with
/// the cloud's normals, on a copy of the cloud in a spatial (Morton) order, the results taken
/// back to the cloud's rows: each point reads its neighbours' rows, which a cloud in no spatial
/// order scatters over memory, and on the copy they lie near each other. The results are those
/// of the cloud in its own order, bit for bit (ties by its rows).
#include <cmath>
#include <optional>
#include <vector>

#include "focal/core/fields.h"
#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/cloud_normals.h"

namespace focal {

/// Default neighbours per point, chosen by measurement on the analytic clouds (docs/POINTS.md).
inline constexpr int default_cloud_neighbours = 16;

/// Outlier ratio of the default: the ratio on the points of the analytic clouds (8 surfaces,
/// Poisson-disk samples of 3000 and 20000 points, seeds 1 and 2, clean, 10% position noise,
/// graded density 0.5) was at most 1.60, on uniformly random samples of a sphere (2000 to 1M
/// points, seeds 1-3) at most 1.97, growing with the count: 3 leaves 50% over it. Ratios 2 and 3
/// gave the same errors on the analytic clouds with 2% outliers (docs/POINTS.md).
inline constexpr double default_outlier_ratio = 3.0;

/// Off-surface ratio of the default (off_surface_points over the 16 nearest, the statistical
/// outliers left out of the lists): the largest ratio of a point on the surface over the 8
/// analytic clouds (3000 points, seeds 1 and 2, clean, 10% position noise, graded density 0.5
/// and 2% outliers) was below 6.0 (noisy; clean and graded below 3.5), at 30000 noisy points
/// below 8.25 (the torus): 10 flags no point on a surface there. 10 against 20 lowered the
/// H error of every 2% outlier case, 12 none (docs/notes/points-log.md, "Near-surface outliers").
inline constexpr double default_off_surface_ratio = 10.0;

struct CloudOptions {
  /// Neighbours per point (k nearest); 0 (with radius 0) = the adaptive default above.
  /// Ignored when radius > 0.
  int k = 0;
  /// > 0: the neighbours within this distance instead of the k nearest (at most 1024, the
  /// nearest).
  double radius = 0.0;
  /// > 0 (with radius 0): neighbourhoods whose radius follows the local density, this many
  /// times the smoothed distance to the k-th nearest (k, or 16 when k is 0; at most 1024
  /// neighbours): adaptive_radius_neighbours. 0 = off.
  double adaptive_radius = 0.0;
  /// How normals are estimated when the cloud has none (normals/cloud_normals.h).
  CloudNormalOptions normals{};
  Solver solver = Solver::closed_form;
  LevenbergMarquardtOptions levenberg_marquardt{};
  /// The classes' tolerances (core/point_class.h); the zero tolerance in units of the cloud's
  /// mean spacing.
  Tolerances tolerances{};
  /// Points whose mean distance to their 16 nearest exceeds this many times their neighbours'
  /// median of the same are outliers, left out (points/neighbours.h, outlier_points); 0 keeps
  /// every point. See default_outlier_ratio.
  double outlier_ratio = default_outlier_ratio;
  /// Points farther from the plane of their 16 nearest (the statistical outliers left out) than
  /// this many times those neighbours' median distance to it are outliers too, left out as the
  /// statistical ones (points/neighbours.h, off_surface_points); 0 = off. See
  /// default_off_surface_ratio.
  double off_surface_ratio = default_off_surface_ratio;
  /// false: CloudCurvature::neighbours is left empty, for callers that do not read the lists
  /// (the focal command, Python's cloud_curvature). A cloud fitted on its copy in Morton order
  /// (above) takes its lists back to its own rows only when they are kept: the lists are not
  /// taken back for callers that do not read them.
  bool keep_neighbours = true;
};

/// The fields and what they were computed from.
struct CloudCurvature {
  CurvatureResult curvature;
  RowMatrixX3d N;                  ///< #V x 3 unit normals used (given or estimated); NaN rows
  bool normals_estimated = false;  ///< true when N was estimated (the cloud had none)
  Neighbourhoods neighbours;       ///< the neighbourhoods of the fit (and of the normals); empty
                                   ///< without CloudOptions::keep_neighbours
  double spacing = 0.0;            ///< mean_spacing of the cloud
  /// The default's plan: the median jet residual over the spacing (NaN when not measured), the
  /// neighbours of the fit, and whether the cloud's own normals were used.
  double noise = NAN;
  int k = 0;
  bool file_normals_used = false;
  /// The default's step 5: the corrected step on local triangulations (clean positions, no
  /// outlier flagged).
  bool corrected = false;
  /// #V flags of the points left out as outliers, statistical or off the surface (empty when
  /// CloudOptions::outlier_ratio and off_surface_ratio are 0).
  std::vector<char> outlier;
};

/// Curvature of the cloud V (#V x 3) with optional normals N (#V x 3, outward).
/// \throw InvalidInput when N does not have #V rows or an option is out of range.
[[nodiscard]] CloudCurvature estimate_cloud_curvature(PositionsRef V,
                                                      std::optional<NormalsRef> N = std::nullopt,
                                                      const CloudOptions& options = {});

/// The normals estimate_cloud_curvature fits with, without the fit (`focal normals` on a cloud).
/// With the default's plan (k, radius and adaptive_radius 0): its normals (steps 1-3 above: jet
/// normals over the 16 nearest, or quadratic jets over 64 where the positions are noisy; N
/// itself where it agrees with them, else the jets on N's side), unit, NaN rows for the outliers
/// left out and for points without a normal. With k, radius or adaptive_radius: cloud_normals
/// over those neighbourhoods (every point; no outlier test), each turned to the side of its row
/// of N where N is given and options.normals has no viewpoint.
/// \throw InvalidInput as estimate_cloud_curvature.
[[nodiscard]] RowMatrixX3d estimate_cloud_normals(PositionsRef V,
                                                  std::optional<NormalsRef> N = std::nullopt,
                                                  const CloudOptions& options = {});

/// The neighbourhoods CloudOptions select (k nearest or radius).
/// \throw InvalidInput when k < 0 or radius < 0.
[[nodiscard]] Neighbourhoods cloud_neighbourhoods(PositionsRef V, const CloudOptions& options);

/// The two halves of estimate_cloud_curvature, for tiles (focal/tiles/tiles.h): the plan, which
/// reads the whole cloud (the neighbourhoods, outliers, spacing, noise, normals and which are used:
/// every field but `curvature`, N not yet made unit), ...
/// \throw InvalidInput as estimate_cloud_curvature.
[[nodiscard]] CloudCurvature plan_cloud_curvature(PositionsRef V,
                                                  std::optional<NormalsRef> N = std::nullopt,
                                                  const CloudOptions& options = {});

/// ... and the fit of every point over plan.neighbours with plan.N (made unit here, in place)
/// and plan.spacing, into plan.curvature. Each point's row reads only its own and its
/// neighbours' positions and normals. plan_cloud_curvature then fit_cloud_curvature is
/// estimate_cloud_curvature.
void fit_cloud_curvature(PositionsRef V, CloudCurvature& plan, const CloudOptions& options);

/// The neighbourhoods of a plan's fit: the k nearest (CloudCurvature::k of the plan), or those
/// within options.radius when it is > 0, leaving out the points flagged in `excluded` (#V flags,
/// or empty): plan.neighbours, computed on any subset of the cloud that holds a point's
/// neighbours gives that point's list (ties broken by index, so in the subset's order when it
/// keeps the cloud's).
[[nodiscard]] Neighbourhoods cloud_fit_neighbourhoods(PositionsRef V, const CloudOptions& options,
                                                      int k, const std::vector<char>& excluded);

}  // namespace focal
