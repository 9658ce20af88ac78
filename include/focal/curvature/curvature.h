#pragma once
/// \file curvature.h
/// Per-vertex curvature fields by focal surfaces (Yu et al., SGP 2007): principal curvatures
/// k1 >= k2, principal directions d1, d2, mean and Gaussian curvature, fit residual and class.
///
/// Conventions: outward normals; curvature positive where the surface bends away from the normal
/// (sphere of radius r: k1 = k2 = +1/r); d1 belongs to k1; d1, d2 are unit 3D vectors tangent to
/// the vertex normal, and (d1, d2, N) is right-handed.

#include "focal/core/fields.h"
#include "focal/core/mesh.h"
#include "focal/curvature/two_slit_fit.h"
#include "focal/mesh/prepared.h"

namespace focal {

/// Classifies principal curvatures: |k| <= zero_tolerance counts as zero; k1 - k2 <=
/// umbilic_tolerance * max(|k1|, |k2|) counts as umbilic. NaN gives `undefined`.
[[nodiscard]] PointClass classify(double k1, double k2, double zero_tolerance,
                                  double umbilic_tolerance);

enum class Method {
  vertex,    ///< per-vertex two-slit fit over a ring neighbourhood (paper section 5)
  triangle,  ///< per-triangle characteristic equation, area-averaged to vertices (paper 4.3, 5.1)
};
enum class Solver {
  closed_form,          ///< global minimum of the paper's objective in closed form (default)
  levenberg_marquardt,  ///< the paper's sampled-angle Levenberg-Marquardt, for reproduction
};
enum class RayWeighting {
  uniform,   ///< every neighbour ray counts the same (the paper)
  gaussian,  ///< weight exp(-d^2 / (2 s^2)), d the distance to the vertex, s = gaussian_width
};

/// Options of the paper's estimator, estimate_curvature (and of triangle_curvature and the
/// baselines, which read the fields they name). Defaults reproduce the paper with the closed-form
/// solver.
struct CurvatureOptions {
  Method method = Method::vertex;
  Solver solver = Solver::closed_form;
  int rings = 1;  ///< neighbourhood size in rings (1 = the paper's default, 2 = its Fig. 9c)
  RayWeighting weighting = RayWeighting::uniform;
  /// Width s of the Gaussian weights; 0 = the mesh's mean edge length times `rings`.
  double gaussian_width = 0.0;
  LevenbergMarquardtOptions levenberg_marquardt;
  /// The classes' tolerances (core/point_class.h).
  Tolerances tolerances{};
};

/// Estimates the curvature fields of a triangle mesh from its vertex normals: the paper's method.
/// \param mesh with #V x 3 outward normals (rows are normalised; zero or non-finite rows make
///        their vertex `undefined`).
/// \throw InvalidInput when the mesh has no normals or an option is out of range.
[[nodiscard]] CurvatureResult estimate_curvature(const PreparedMesh& mesh,
                                                 const CurvatureOptions& options = {});

/// estimate_curvature of the arrays. \param V #V x 3 positions. \param F #F x 3 triangles.
/// \param N #V x 3 outward normals, as above.
/// \throw InvalidInput when shapes differ, F indexes outside V, or an option is out of range.
[[nodiscard]] CurvatureResult estimate_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                                 const CurvatureOptions& options = {});

}  // namespace focal
