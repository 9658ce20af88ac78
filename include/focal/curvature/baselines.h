#pragma once
/// \file baselines.h
/// Curvature estimators from the literature, as references for the evaluation: the two the paper
/// compares with (section 6), the two its section 7 names as future comparisons (integral
/// invariants, the mid-edge shape operator) and the interpolated corrected curvature measures.
/// All return the same CurvatureResult as the focal estimator, with the same conventions (outward
/// orientation from the faces, or from the given normals for LRTC20; sphere of radius r:
/// k1 = k2 = +1/r, d1 of k1, (d1, d2, n) right-handed where n is the vertex normal, the
/// area-weighted one unless a function names another) and the same classes and tolerances.

#include <optional>

#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"

namespace focal::baselines {

/// MDSB03: Meyer, Desbrun, Schroeder, Barr, "Discrete differential-geometry operators for
/// triangulated 2-manifolds" (2003). Mean curvature from the cotangent Laplacian over the mixed
/// Voronoi area (sign from the area-weighted normal), Gaussian curvature from the angle defect
/// (2 pi at interior vertices, pi on the boundary), k1,2 = H +- sqrt(max(H^2 - K, 0)), and the
/// principal directions from their least-squares fit of a curvature tensor with trace 2H to the
/// normal curvatures 2 (x_i - x_j).n / |x_i - x_j|^2 of the edges, weighted by each edge's share
/// of the Voronoi area. Uses options.tolerances.
/// \throw InvalidInput when F indexes outside V.
[[nodiscard]] CurvatureResult meyer_2003(PositionsRef V, FacesRef F,
                                         const CurvatureOptions& options = {});

/// CSM03: Cohen-Steiner and Morvan, "Restricted Delaunay triangulations and normal cycle"
/// (2003): T = (1 / area(B)) sum_e beta(e) |e| e e^T over the edges of the faces of a
/// neighbourhood B (the faces within options.rings - 1 rings of the vertex; 1 = its incident
/// faces), beta(e) the signed dihedral angle (positive on convex edges). The eigenvector of T
/// closest to the vertex normal is dropped; the other two eigenvalues are the principal
/// curvatures, each belonging to the other's eigenvector (the normal cycle's tensor is rotated
/// by 90 degrees). Uses options.rings and options.tolerances.
/// \throw InvalidInput when F indexes outside V or options.rings < 1.
[[nodiscard]] CurvatureResult cohen_steiner_morvan_2003(PositionsRef V, FacesRef F,
                                                        const CurvatureOptions& options = {});

/// The ball B(x_i, r) around each vertex of the ball-based baselines below.
struct BallOptions {
  /// Radius in the mesh's units; 0 takes `radius_in_edges` x the mesh's mean edge length.
  double radius = 0.0;
  /// The radius in mean edge lengths when `radius` is 0 (each function states its default).
  double radius_in_edges = 0.0;
};

/// LRTC20: interpolated corrected curvature measures, Lachaud, Romon, Thibert, Coeurjolly,
/// "Interpolated corrected curvature measures for polygonal surfaces" (SGP 2020), and Lachaud
/// et al., "Corrected curvature measures" (DCG 2022); our own implementation from the papers
/// (CGAL 6 has one, Debian 12 ships CGAL 5.5). Per triangle (x_i, x_j, x_k) with the vertex
/// normals u linearly interpolated, the closed forms of the area mu0, mean mu1, Gauss mu2 and
/// anisotropic muXY measures (written out in src/curvature/baselines/lachaud_2020.cpp) are summed
/// over the ball B(x_i, r), each triangle weighted by an estimate of the fraction of its area in
/// the ball: 1 with its three corners inside, 0 with none, else (r - d_min) / (d_max - d_min),
/// d the corners' distances to x_i (linear in the distance; triangles reached from x_i through
/// corners inside the ball). H = mu1 / (2 mu0), K = mu2 / mu0 (stored as they are, not as
/// k1 k2); k1, k2, d1, d2 from -sym(muXY) / mu0 projected to the plane of u_i (n = u_i).
/// \param N #V x 3 outward normals (normalised per row), or std::nullopt for Max's (1999)
///        face-weighted normals.
/// Ball: default radius 1 mean edge length (docs/METHOD.md, "Baselines"). Uses
/// options.tolerances.
/// \throw InvalidInput when F indexes outside V, N has not #V rows, or the radius is negative or
/// not finite.
[[nodiscard]] CurvatureResult lachaud_2020(PositionsRef V, FacesRef F,
                                           std::optional<NormalsRef> N = std::nullopt,
                                           const BallOptions& ball = {},
                                           const CurvatureOptions& options = {});

/// YLHP06: integral invariants, Yang, Lai, Hu, Pottmann, "Robust principal curvatures on
/// multiple scales" (SGP 2006), in its surface-patch form: the covariance C of the mesh inside
/// the ball B(x_i, r) (triangles clipped to the ball exactly at their corners and edges, the
/// arcs inside a triangle replaced by chords). The surface being locally z = -(k1 x^2 + k2 y^2)/2
/// along the outward normal n, to leading order in r the centroid m and the normal variance
/// n^T C n give k1 + k2 = -8 <m - x_i, n> / r^2 and 3 (k1 + k2)^2 - 8 k1 k2 = 192 n^T C n /
/// (pi r^6) (both exact on a sphere); n is the eigenvector of C of the smallest eigenvalue,
/// oriented by the area-weighted normal, and the curvature of larger magnitude belongs to the
/// tangent eigenvector of C with the smaller eigenvalue. Error O(r^2) from the truncated
/// expansion plus O(h^2 / r^2) from the discretisation (h the edge length). Positions only.
/// Ball: default radius 4 mean edge lengths (docs/METHOD.md, "Baselines"). Uses
/// options.tolerances.
/// \throw InvalidInput when F indexes outside V or the radius is negative or not finite.
[[nodiscard]] CurvatureResult yang_2006(PositionsRef V, FacesRef F, const BallOptions& ball = {},
                                        const CurvatureOptions& options = {});

/// GGRZ06: the mid-edge shape operator of Grinspun, Gingold, Reisman, Zorin, "Computing discrete
/// shape operators on general meshes" (Eurographics 2006). Per face, with unit normal N, area A,
/// edges e_j and t_j = e_j x N / |e_j| (in-plane, pointing out of the face), and the mid-edge
/// normal n_j the normalised mean of the two face normals at e_j (the face's own on a boundary
/// edge): S = (1 / A) sum_j |e_j| <n_j, t_j> t_j t_j^T, the gradient of the normals linearly
/// interpolated from the edge midpoints (positive on a sphere with outward normals). A vertex
/// averages the operators of its incident faces by area, each rotated by the smallest rotation
/// taking its face normal to the area-weighted vertex normal. Positions only. Uses
/// options.tolerances.
/// \throw InvalidInput when F indexes outside V.
[[nodiscard]] CurvatureResult grinspun_2006(PositionsRef V, FacesRef F,
                                            const CurvatureOptions& options = {});

}  // namespace focal::baselines
