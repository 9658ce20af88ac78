#pragma once
// Internal: the recommended estimator's second-order step on trusted normals (corrected_step.cpp).

#include <Eigen/Core>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/prepared.h"

namespace focal::detail {

/// How far a vertex's 1-ring is from central symmetry: the mean, over its neighbours j, of
/// |P (e_j + e_k)| / |e_j| for the neighbour k that best opposes j (e = neighbour - vertex, P the
/// projection onto the plane of the unit normal N.row(i)); 0 on a grid whose every edge has an
/// opposite twin (regular and strip grids, lat-long rows), about 0.3 to 0.5 on random samplings.
/// Per vertex, then averaged over the closed 1-ring. NaN where the normal is not finite or the
/// vertex has no neighbour.
Eigen::VectorXd stencil_asymmetry(PositionsRef V, const RowMatrixX3d& N,
                                  const Neighbourhoods& one_ring, int threads);

/// Asymmetry (stencil_asymmetry) below which a vertex counts as on a symmetric stencil. The two
/// populations do not overlap on the evaluation's meshes: interior vertices of regular, strip
/// and lat-long grids measure below 0.2 (grid boundaries and pole fans up to 0.35), of random
/// samplings above 0.26 (minimum; 0.29 at the 1st percentile). A vertex on the wrong side takes
/// the other estimate (the per-triangle pass or the corrected measures): errors of the same
/// order, not a failure.
constexpr double kSymmetricStencil = 0.25;

/// Ball radius of the corrected step, in lengths of the vertex's own edges (their mean): it
/// reaches into the 2-ring's faces and averages the first-order errors of an irregular sampling
/// out. Measured on `focal eval --suite hard`, seeds 1 and 2 (in mean edge lengths): half an
/// edge loses the irregular cases (graded torus 0.0055 vs 0.0045), 1.5 and 2 edges the coarse
/// meshes (median 0.030 and 0.045 vs 0.017); a ball in the
/// mesh's mean edge length instead of the local one loses the graded meshes (median 0.0073 vs
/// 0.0057). Symmetric stencils keep the per-triangle pass (docs/notes/estimator-log.md, "The corrected
/// step": half an edge there won on strip grids and lost on regular ones).
constexpr double kCorrectedBall = 1.0;

/// Rings a corrected-step ball reaches at most (ball::gather's cap; recommended_reach).
constexpr int kCorrectedBallRings = 3;

/// The second-order step of the recommended estimator on trusted normals (file normals that
/// agree with the positions, on clean positions): LRTC20's interpolated corrected curvature
/// measures (baselines.h) of the fitted normals `fitted.normals()` over a ball of kCorrectedBall
/// local edge lengths, into the rows of `fit` at vertices whose stencil is not symmetric
/// (stencil_asymmetry at least kSymmetricStencil), except where `fit` is exact (residual at or
/// below `exact_residual`), where `keep` is set (crease neighbourhoods) or where the measures are
/// undefined.
void prefer_corrected_measures(const PreparedMesh& fitted, const Neighbourhoods& one_ring,
                               const CurvatureOptions& options, const std::vector<char>& keep,
                               double exact_residual, CurvatureResult& fit);

/// The rows prefer_corrected_measures would write: the measures, and per vertex whether they
/// replace the row of `fit` (known before `fit`'s rows from the per-triangle pass are, which
/// then need computing only where this is 0: `fit` is read for its residual only). `values` is
/// empty (0 rows) when no row replaces for want of a ball (every stencil symmetric).
struct CorrectedRows {
  CurvatureResult values;
  std::vector<char> replace;
};
CorrectedRows corrected_rows(const PreparedMesh& fitted, const Neighbourhoods& one_ring,
                             const CurvatureOptions& options, const std::vector<char>& keep,
                             double exact_residual, const CurvatureResult& fit);

/// corrected_rows with `asymmetry` = stencil_asymmetry of `fitted`'s unit normals given: the
/// recommended estimator computes it before the fit, whose whole-mesh result would otherwise be
/// alive beside the asymmetry's two arrays (the peak of its run). Its memory becomes the radii.
CorrectedRows corrected_rows(const PreparedMesh& fitted, const Neighbourhoods& one_ring,
                             const CurvatureOptions& options, const std::vector<char>& keep,
                             double exact_residual, const CurvatureResult& fit,
                             Eigen::VectorXd asymmetry);

/// Writes the rows of `rows` that replace into `fit`.
void apply_corrected_rows(const CorrectedRows& rows, int threads, CurvatureResult& fit);

/// A fit residual (RMS ray misfit, slope units) at or below this is rounding: the rays meet two
/// slits exactly (spheres, cylinders, planes), and so does the fit, which the later steps keep.
constexpr double kExactFitResidual = 1e-9;

/// The corrected step of the cloud default (docs/notes/points-log.md, "The corrected step on clouds"): a
/// cloud has no faces, so each point gets a local triangulation of its own, the Delaunay
/// triangulation of it and its neighbours projected onto its tangent plane (points/
/// natural_ring.h; its natural neighbours are its 1-ring). At each point i that is not skipped
/// (`skip[i]`), whose normal is usable (`ok`) and whose fit is not exact (`fit` residual above
/// kExactFitResidual), LRTC20's corrected measures of the unit normals N over the ball of
/// kCorrectedBall local edge lengths (the mean distance to its natural neighbours) about it, on
/// the triangles of that triangulation at the points within the ball reached from i along its
/// edges (at most kCorrectedBallRings edges away), as the mesh's ball reaches its faces. Only
/// neighbours j with ok[j] and a normal in the hemisphere of N.row(i) take part. Reads only i's
/// and its neighbours' positions and normals (tiles with a halo of one link give the same
/// rows); writes row i of `fit` where the measures are defined (a positive area in the ball),
/// leaves it otherwise. `scale`: the cloud's spacing, the scale of the class tolerances.
/// `order`: the points in the order to visit them (a permutation of the rows, or empty: row
/// order); each point reads and writes its own row of `fit` only, so any order gives the same.
void cloud_corrected_measures(PositionsRef V, const RowMatrixX3d& N, const std::vector<char>& ok,
                              const Neighbourhoods& neighbours, const std::vector<char>& skip,
                              const CurvatureOptions& options, double scale,
                              const std::vector<int>& order, CurvatureResult& fit);

}  // namespace focal::detail
