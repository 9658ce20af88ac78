#pragma once
/// \file normal_estimation.h
/// Vertex normals (and curvature) from positions by local polynomial height fits, "osculating
/// jets" (Cazals and Pouget, "Estimating differential quantities using polynomial fitting of
/// osculating jets", SGP 2003).
///
/// Why: normals averaged from face normals (vertex_normals.h: area, angle, Max weights) are exact
/// on spheres and second-order accurate on symmetric (regular) stencils, but only first-order
/// accurate on irregular meshes, and the focal-surface fit differentiates the normal field, so a
/// first-order normal error becomes an O(1) curvature error that does not shrink with refinement.
/// A least-squares polynomial of degree d fitted to the heights of the k-ring over the tangent
/// plane has a gradient error O(h^d) on any triangulation: degree 2 gives second-order normals,
/// degree 3 third order. Least squares also averages position noise over the neighbourhood.
///
/// Per vertex P, with frame (x, y, n) (normal_rays.h) whose n is the previous estimate (first
/// the Max-weighted normal): the k-ring and P itself, as offsets q = Q - P scaled by the
/// neighbourhood radius, give heights z = q.n over (q.x, q.y); the full polynomial of degree d
/// (constant term included, so P's own position is smoothed like the others) is fitted by least
/// squares (normal equations from the points' moments, LDL^T with diagonal pivoting). The normal is
/// that of the graph at (0, 0): (-z_x, -z_y, 1) normalised in the frame. Each further iteration
/// refits in the frame of the new normal. Where the k-ring has too few points for degree d (a valid
/// fit needs full column rank), lower degrees are tried down to 1 (a plane); a vertex with no valid
/// fit or no Max normal (in no face) gets NaN.
///
/// Results are gathered per vertex in fixed order: identical for any thread count.

#include "focal/core/fields.h"
#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/prepared.h"

namespace focal {

struct JetOptions {
  int rings = 2;       ///< neighbourhood of the fit in rings (>= 1)
  int degree = 2;      ///< degree of the height polynomial, 1 to 4
  int iterations = 2;  ///< fits per vertex (>= 1); each refits in the previous fit's frame
};

/// Normals from jets, and how well the jets fit.
struct JetNormals {
  RowMatrixX3d N;  ///< #V x 3 unit normals, oriented like the faces; NaN rows where undefined
  /// #V root-mean-square height residual of the last fit, sqrt(SSR / (n - m)) for n points and
  /// m coefficients (length units; NaN where undefined or n == m): an estimate of the position
  /// noise normal to the surface plus the fit's truncation error.
  Eigen::VectorXd residual;
  Eigen::VectorXi degree;  ///< #V degree actually fitted (0 where undefined)
};

/// Jet normals of every vertex, from the mesh's kept incidence (and 1-ring, when kept).
/// \throw InvalidInput when rings < 1, degree outside [1, 4], or iterations < 1.
[[nodiscard]] JetNormals jet_normals(const PreparedMesh& mesh, const JetOptions& options = {});

/// Jet normals of the arrays. \throw also InvalidInput when F indexes outside V.
[[nodiscard]] JetNormals jet_normals(PositionsRef V, FacesRef F, const JetOptions& options = {});

/// The same with the mesh's 1-ring (vertex_adjacency(#V, F)) at hand, which it then does not
/// rebuild. \throw also InvalidInput when one_ring does not have #V vertices.
[[nodiscard]] JetNormals jet_normals(PositionsRef V, FacesRef F, const Neighbourhoods& one_ring,
                                     const JetOptions& options = {});

/// The same with the starting normals at hand too: `start` (#V x 3) gives the frame of each
/// vertex's first fit, vertex_normals(V, F, NormalWeighting::max) in the overloads above (pass
/// those to get the same result without computing them twice, e.g. when the caller needs Max's
/// normals itself). Non-finite rows give NaN (no jet).
/// \throw also InvalidInput when start does not have #V rows or a finite row is not of unit
/// length within 1e-6.
[[nodiscard]] JetNormals jet_normals(PositionsRef V, FacesRef F, const Neighbourhoods& one_ring,
                                     NormalsRef start, const JetOptions& options = {});

/// Curvature from the jets (a positions-only reference in the spirit of CGAL's jet fitting):
/// the shape operator of the fitted graph at (0, 0) of the last fit, with focal's conventions
/// (sphere of radius r with outward normals: +1/r; d1 of k1; (d1, d2, N) right-handed with N the
/// jet normal). Needs degree >= 2: vertices fitted with a lower degree are `undefined`.
/// residual = the jet's height residual. rays_used = points in the fit, rays_excluded = 0.
/// \throw as jet_normals, and InvalidInput when options.degree < 2.
[[nodiscard]] CurvatureResult jet_curvature(const PreparedMesh& mesh,
                                            const JetOptions& options = {});

/// jet_curvature of the arrays.
[[nodiscard]] CurvatureResult jet_curvature(PositionsRef V, FacesRef F,
                                            const JetOptions& options = {});

}  // namespace focal
