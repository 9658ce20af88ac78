#pragma once
/// \file surfaces.h
/// Analytic test surfaces with exact differential geometry, triangulated regularly or
/// irregularly, and the noise models of the paper's Fig. 10. Used by the tests, by
/// `focal generate` and by the accuracy evaluation.
///
/// Every surface gives per vertex: the position, the exact unit outward normal, the exact
/// principal curvatures k1 >= k2 (sphere of radius r: +1/r) and unit principal directions d1, d2
/// (d1 belongs to k1; tangent, orthogonal; arbitrary but orthonormal at umbilics).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "focal/mesh.h"

namespace focal {

enum class SurfaceKind {
  sphere,         ///< radius a (closed)
  ellipsoid,      ///< semi-axes a, b, c (closed)
  torus,          ///< major radius a, minor radius b (closed)
  cylinder,       ///< radius a, height b (open: two boundary circles)
  saddle,         ///< z = (x^2 - y^2) / 2 over the square [-a, a]^2 (open)
  monkey_saddle,  ///< z = (x^3 - 3 x y^2) / 2 over the disc of radius a (open)
  helix_tube,     ///< tube of radius b around the helix (a cos t, a sin t, c t), two turns (open)
  pear,           ///< closed pear-shaped surface of revolution
};

/// Lower-case names as used on the command line: sphere, ellipsoid, torus, cylinder, saddle,
/// monkey-saddle, helix-tube, pear.
[[nodiscard]] std::string_view surface_name(SurfaceKind kind);
/// \throw InvalidInput for an unknown name (the message lists the known ones).
[[nodiscard]] SurfaceKind surface_from_name(std::string_view name);
[[nodiscard]] std::vector<SurfaceKind> all_surfaces();

enum class Triangulation {
  regular,    ///< a regular parameter grid, two triangles per cell, seams and poles welded
  irregular,  ///< random well-spaced samples, Delaunay-quality triangles, seams welded
};

struct SurfaceOptions {
  SurfaceKind kind = SurfaceKind::sphere;
  Triangulation triangulation = Triangulation::regular;
  int target_vertices = 2000;  ///< approximate vertex count (the result is close, not exact)
  std::uint64_t seed = 1;      ///< for irregular sampling; same seed, same mesh
  /// Shape parameters; 0 selects the documented default of each surface
  /// (sphere a=1; ellipsoid 1, 0.8, 0.6; torus 1, 0.4; cylinder 1, 2; saddle a=1;
  /// monkey saddle a=1; helix tube a=1, b=0.25, c=0.3; pear: see surfaces.cpp).
  double a = 0, b = 0, c = 0;
};

/// A triangulated analytic surface with its exact truth per vertex.
struct AnalyticSurface {
  Mesh mesh;          ///< positions, faces (outward orientation) and exact unit normals in mesh.N
  Eigen::VectorXd k1;  ///< exact principal curvatures, k1 >= k2
  Eigen::VectorXd k2;
  RowMatrixX3d d1;     ///< exact unit principal directions
  RowMatrixX3d d2;
};

/// \throw InvalidInput when target_vertices < 16 or a shape parameter is invalid.
[[nodiscard]] AnalyticSurface make_surface(const SurfaceOptions& options);

/// Paper Fig. 10 vertex noise: each position moves by a vector whose components are uniform in
/// [-amplitude, amplitude] x mean edge length (default 0.1). Normals are left as they are.
void add_position_noise(Mesh& mesh, double amplitude, std::uint64_t seed);

/// Paper Fig. 10 normal noise: n' = normalize(n + u), u uniform in [-amplitude, amplitude]^3
/// (default 0.05). Positions are left as they are.
void add_normal_noise(Mesh& mesh, double amplitude, std::uint64_t seed);

}  // namespace focal
