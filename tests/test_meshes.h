#pragma once
// Small meshes and error measures shared by the estimator tests.

#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/surfaces/surfaces.h"

namespace focal::test {

/// An n x n grid of unit squares in the plane z = 0, two triangles each, normals +z.
inline Mesh flat_grid(int n, double spacing = 1.0) {
  Mesh m;
  m.V.resize(n * n, 3);
  m.N.resize(n * n, 3);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      m.V.row(y * n + x) << x * spacing, y * spacing, 0.0;
      m.N.row(y * n + x) << 0.0, 0.0, 1.0;
    }
  }
  m.F.resize(2 * (n - 1) * (n - 1), 3);
  int f = 0;
  for (int y = 0; y + 1 < n; ++y) {
    for (int x = 0; x + 1 < n; ++x) {
      const int a = y * n + x, b = a + 1, c = a + n, d = c + 1;
      m.F.row(f++) << a, b, d;
      m.F.row(f++) << a, d, c;
    }
  }
  return m;
}

/// An analytic surface with the given triangulation, about `vertices` vertices, first shape
/// parameter `a` (0 = default) and seed.
inline AnalyticSurface analytic_surface(SurfaceKind kind, Triangulation triangulation, int vertices,
                                        double a, std::uint64_t seed) {
  SurfaceOptions o;
  o.kind = kind;
  o.triangulation = triangulation;
  o.target_vertices = vertices;
  o.a = a;
  o.seed = seed;
  return make_surface(o);
}

/// Vertices at least `rings` rings away from any boundary (all vertices of closed meshes).
inline std::vector<int> interior_vertices(const Mesh& m, int rings) {
  const Neighbourhoods one = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
  const Eigen::VectorXi d =
      rings_to_boundary(one, boundary_vertices(static_cast<int>(m.V.rows()), m.F), rings);
  std::vector<int> out;
  for (int i = 0; i < d.size(); ++i) {
    if (d[i] > rings) out.push_back(i);
  }
  return out;
}

/// Root-mean-square of (estimate - truth) over the given vertices.
inline double rms_error(const Eigen::VectorXd& estimate, const Eigen::VectorXd& truth,
                        const std::vector<int>& at) {
  double sum = 0.0;
  for (int i : at) sum += (estimate[i] - truth[i]) * (estimate[i] - truth[i]);
  return std::sqrt(sum / static_cast<double>(at.size()));
}

inline double rms(const Eigen::VectorXd& v, const std::vector<int>& at) {
  double sum = 0.0;
  for (int i : at) sum += v[i] * v[i];
  return std::sqrt(sum / static_cast<double>(at.size()));
}

/// Angle in degrees between two lines (directions modulo sign).
inline double line_angle_degrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
  return std::acos(c) * 180.0 / 3.14159265358979323846;
}

}  // namespace focal::test
