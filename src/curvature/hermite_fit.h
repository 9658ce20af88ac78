#pragma once
// Internal: the recommended estimator's fourth-order step on trusted normals (hermite_fit.cpp).

#include <vector>

#include "core/simd_lanes.h"
#include "curvature/vertex_rows.h"
#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"
#include "focal/mesh/neighbourhood.h"
#include "mesh/topology.h"

namespace focal::detail {

/// Largest angle between a vertex's normal and a neighbour's for the Hermite fit (cos 30
/// degrees). The height of the surface over the vertex's tangent plane is a power series in
/// the tangential offset over the curvature radius, sin of the turn; the quartic leaves terms of
/// relative size sin^4 (1/16 at 30 degrees) where the per-triangle pass leaves sin^2. Beyond it
/// the 1-ring wraps around the surface (a coarse thin tube) and the quartic loses.
constexpr double kHermiteMaxTurnCosine = 0.8660254037844386;

/// Smallest pivot of the fit's normal equations against the largest (after the rows are made
/// dimensionless): below it the 1-ring does not fix the quartic (a vertex of valence 4 gives 12
/// equations for 12 unknowns, nearly singular on most layouts).
constexpr double kHermiteMinPivot = 1e-12;

/// Largest RMS misfit of the fit's rows (slope units, as the two-slit fit's residual) for its
/// operator to be used. On clean meshes with exact normals the quartic meets the rows to within
/// its truncation: at most 0.005 (measured on the hard suite's clean cases: 20:1 strips 0.005,
/// coarse meshes 0.003, others below 0.001); a spike's height or a wild normal left in the ring
/// shows as 0.01 to 0.6, and the per-triangle pass there stays.
constexpr double kHermiteMaxMisfit = 0.005;

/// Rows a 1-ring fit has beyond its unknowns (a 1-ring of 5 neighbours: 15 rows for 12) for its
/// misfit alone to judge it; with fewer (a neighbour whose normal is guessed gives one row,
/// not three; a free height or gradient adds unknowns) it must agree with the 2-ring's
/// (kHermiteAgreement).
constexpr int kHermiteSpareRows = 3;

/// Largest difference, relative to the 2-ring's, between the operators of a vertex's 1-ring
/// and 2-ring fits for the 1-ring's to stand where the gradient is free (a guessed normal) or
/// rows are few (kHermiteSpareRows): on
/// clean meshes the two differ by their truncation, a few percent; a spike or a wild normal in
/// the 1-ring, which its few spare rows cannot show, by far more (the spiked helix tube with
/// outlier normals: 5 times H).
constexpr double kHermiteAgreement = 0.1;

/// The quartic Hermite fit of a vertex's closed 1-ring: the height h(x, y) over the tangent
/// plane of the vertex's unit normal, h = sum of the 12 monomials of degree 2 to 4 (h and its
/// gradient vanish at the vertex: the normal is the plane's), fitted in least squares to each
/// neighbour's height and to the two slopes its normal gives (-m_x / m_z, -m_y / m_z), each row
/// divided by the neighbour's distance (heights by its square) so that every row is a
/// curvature. The shape operator is minus h's Hessian at the vertex. With exact normals its
/// error is third order in the edge length (the per-triangle pass and the 1-ring fit: first
/// and second), on irregular, strip and graded meshes alike.
///
/// Writes the rows of `fit` at vertices with `ok` normals whose 1-ring is closed (as many
/// faces as neighbours in `incidence`), where `keep` (empty or #V flags) is not set and the
/// row's residual is above `exact_residual` (the two-slit fit is exact there already). The
/// stencil is the 1-ring, or the 2-ring where the 1-ring does not fix the quartic
/// (kHermiteMinPivot; a vertex of valence 4): at least 5 and at most 96 points, all with `ok`
/// normals within kHermiteMaxTurnCosine of the vertex's, whose quartic meets its rows
/// (kHermiteMaxMisfit). Two kinds of vertices know less (each empty or #V flags): `moved`
/// positions are known to third order only (repaired spikes): they are in no other stencil,
/// and their own fits take the height at the vertex as one more unknown; `guessed` normals are
/// estimated from the positions (file normals replaced as outliers): they give their height
/// rows only, and their own fits take the gradient at the vertex as two more unknowns. The row
/// keeps its residual. Returns, per vertex, whether its row was written. `in_lanes`: the
/// vertices whose fit is their 1-ring's alone are fitted several at once, a vertex a SIMD lane,
/// with the same bits (false: each alone, for the tests of that).
std::vector<char> prefer_hermite_fit(PositionsRef V, const RowMatrixX3d& N,
                                     const std::vector<char>& ok, const Neighbourhoods& one_ring,
                                     const VertexFaces& incidence, const std::vector<char>& keep,
                                     const std::vector<char>& moved,
                                     const std::vector<char>& guessed, double exact_residual,
                                     const ClassTolerances& tol, CurvatureResult& fit,
                                     SimdIsa isa = SimdIsa::best, bool in_lanes = true);

}  // namespace focal::detail
