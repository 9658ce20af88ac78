#pragma once
/// \file baselines.h
/// The two curvature estimators the paper compares with (section 6), as references for the
/// evaluation. Both use positions and faces only (no vertex normals) and return the same
/// CurvatureResult as the focal estimator, with the same conventions (outward orientation from
/// the faces, sphere of radius r: k1 = k2 = +1/r, d1 of k1, (d1, d2, n) right-handed where n is
/// the area-weighted vertex normal) and the same classes and tolerances.

#include "focal/curvature/curvature.h"
#include "focal/core/mesh.h"

namespace focal::baselines {

/// MDSB03: Meyer, Desbrun, Schroeder, Barr, "Discrete differential-geometry operators for
/// triangulated 2-manifolds" (2003). Mean curvature from the cotangent Laplacian over the mixed
/// Voronoi area (sign from the area-weighted normal), Gaussian curvature from the angle defect
/// (2 pi at interior vertices, pi on the boundary), k1,2 = H +- sqrt(max(H^2 - K, 0)), and the
/// principal directions from their least-squares fit of a curvature tensor with trace 2H to the
/// normal curvatures 2 (x_i - x_j).n / |x_i - x_j|^2 of the edges, weighted by each edge's share
/// of the Voronoi area. Uses options.zero_tolerance, umbilic_tolerance and threads.
/// \throw InvalidInput when F indexes outside V.
[[nodiscard]] CurvatureResult meyer_2003(PositionsRef V, FacesRef F,
                                         const CurvatureOptions& options = {});

/// CSM03: Cohen-Steiner and Morvan, "Restricted Delaunay triangulations and normal cycle"
/// (2003): T = (1 / area(B)) sum_e beta(e) |e| e e^T over the edges of the faces of a
/// neighbourhood B (the faces within options.rings - 1 rings of the vertex; 1 = its incident
/// faces), beta(e) the signed dihedral angle (positive on convex edges). The eigenvector of T
/// closest to the vertex normal is dropped; the other two eigenvalues are the principal
/// curvatures, each belonging to the other's eigenvector (the normal cycle's tensor is rotated
/// by 90 degrees). Uses options.rings, zero_tolerance, umbilic_tolerance and threads.
/// \throw InvalidInput when F indexes outside V or options.rings < 1.
[[nodiscard]] CurvatureResult cohen_steiner_morvan_2003(PositionsRef V, FacesRef F,
                                                        const CurvatureOptions& options = {});

}  // namespace focal::baselines
