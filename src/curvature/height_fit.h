#pragma once
// Internal: the recommended estimator's fourth-order step on clean positions without trusted
// normals (height_fit.cpp).

#include <vector>

#include "core/simd_lanes.h"
#include "curvature/vertex_rows.h"
#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"
#include "focal/mesh/neighbourhood.h"
#include "mesh/topology.h"

namespace focal::detail {

/// Rows a height fit has beyond its unknowns for its misfit to judge it: a spike or a fold left
/// in a stencil with fewer spare rows is fitted as well as the surface.
constexpr int kHeightSpareRows = 3;

/// Largest RMS misfit of the height fit's rows (each a height over the squared distance, in the
/// units of the stencil's RMS radius: a curvature times that radius) for its operator to be
/// used. The quartic leaves terms of fifth order, (r / R)^3 of the rows on a ring of radius r
/// on a surface of curvature radius R: at most 0.001 on the suites' clean meshes within the
/// turn guard; a spike left in the ring (of a tenth of an edge or more) shows as 0.01 or more.
constexpr double kHeightMaxMisfit = 0.002;

/// Largest share of the cubic's misfit that a vertex's quartic fit may keep (both over the
/// same rows) for its operator to be used. Where the positions are exact the misfits are the
/// fits' truncation, and the quartic's is a small part of the cubic's: medians 0.004 to 0.09
/// over the clean meshes of the suites, 99th percentiles up to 0.53 (coarse and graded pears);
/// where noise dominates, both are the noise: 0.2 to 0.95 at 0.1% of an edge.
constexpr double kHeightMaxShare = 0.5;

/// Largest median share over a mesh's sample (RecommendedMeshWide::height_share) for the fit
/// to run at all: its operator takes second differences of heights, so noise of a thousandth
/// of an edge already costs more than the fit gains (torus, regular grid: 0.006 without it,
/// 0.03 with it), and a mesh's noise shows in the median share before any one vertex's does.
/// Clean meshes of the suites: medians 0.004 to 0.09; vertex noise of 0.1% of an edge and more,
/// and the scans of CGAL's data: 0.2 to 0.83.
constexpr double kHeightMaxMedianShare = 0.15;

/// The quartic height fit of a vertex's 2-ring from positions alone: the height h(x, y) over the
/// tangent plane of the vertex's fitted normal, h = sum of the 14 monomials of degree 1 to 4
/// (h vanishes at the vertex, the gradient is fitted: the normal need not be exact), fitted in
/// least squares to each neighbour's height, every row divided by the squared distance so that
/// every row is a curvature. The shape operator is that of the graph at the vertex (minus the
/// Hessian in the metric of the gradient). Its error is third order in the edge length on
/// irregular meshes, as the Hermite fit's (hermite_fit.h) with exact normals; the 1-ring fit of
/// estimated normals is first order there.
///
/// Writes the rows of `fit` at vertices with `ok` normals whose 1-ring is closed (as many
/// faces as neighbours in `incidence`), where `keep` (empty or #V flags) is
/// not set and the row's residual is above `exact_residual`, whose 2-ring (at most 96 points,
/// less the `moved` ones) has all its `ok` normals within kHermiteMaxTurnCosine of the vertex's,
/// kHeightSpareRows rows to spare and a quartic that meets its rows (kHeightMaxMisfit). `moved`
/// (empty or #V flags): positions known to third order only (repaired spikes); they are in no
/// other stencil, and their own fits take the height at the vertex as one more unknown. The row
/// keeps its residual. Returns, per vertex, whether its row was written. `in_lanes`: the
/// vertices whose height is not free are fitted several at once, a vertex a SIMD lane, with the
/// same bits (false: each alone, for the tests of that).
std::vector<char> prefer_height_fit(PositionsRef V, const RowMatrixX3d& N,
                                    const std::vector<char>& ok, const Neighbourhoods& one_ring,
                                    const VertexFaces& incidence, const std::vector<char>& keep,
                                    const std::vector<char>& moved, double exact_residual,
                                    const ClassTolerances& tol, CurvatureResult& fit,
                                    SimdIsa isa = SimdIsa::best, bool in_lanes = true);

/// The share at v of its quartic fit's misfit in the cubic's (both of its 2-ring's heights in
/// the frame of the unit normal `n`, the turn guard on the `ok` rows of N): the sample's values
/// of RecommendedMeshWide::height_share; NaN where the quartic is refused (an open 1-ring,
/// too few points, a turn past the guard).
double height_truncation_share(PositionsRef V, const RowMatrixX3d& N, const std::vector<char>& ok,
                               const Neighbourhoods& one_ring, const VertexFaces& incidence, int v,
                               const Eigen::Vector3d& n);

}  // namespace focal::detail
