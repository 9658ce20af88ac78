#pragma once
// Closed thin solids sampled as clouds with their outward normals, for the orientation tests:
// each surface stratified at spacing h = 1 (one uniform point in each h x h cell of its
// parameter rectangle, by area), optionally with Gaussian position noise. Thicknesses in
// spacings are what propagation over the k nearest fails on (docs/POINTS.md, "Orientation").

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "focal/core/mesh.h"

namespace focal::test {

struct Solid {
  RowMatrixX3d V, N;  ///< positions and outward unit normals
};

class SolidBuilder {
 public:
  explicit SolidBuilder(std::uint64_t seed) : rng_(seed) {}

  double uniform() { return std::uniform_real_distribution<double>(0.0, 1.0)(rng_); }

  void add(const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
    points_.push_back(p);
    normals_.push_back(n.normalized());
  }

  /// The rectangle corner + u a + v b (u, v in [0, 1]), normal a x b outward.
  void rectangle(const Eigen::Vector3d& corner, const Eigen::Vector3d& a,
                 const Eigen::Vector3d& b) {
    const int nu = std::max(1, static_cast<int>(std::lround(a.norm())));
    const int nv = std::max(1, static_cast<int>(std::lround(b.norm())));
    const Eigen::Vector3d n = a.cross(b);
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        add(corner + (i + uniform()) / nu * a + (j + uniform()) / nv * b, n);
      }
    }
  }

  /// The box [0, l] (l = lx, ly, lz) about `centre`.
  void box(const Eigen::Vector3d& l, const Eigen::Vector3d& centre = Eigen::Vector3d::Zero()) {
    const Eigen::Vector3d o = centre - 0.5 * l;
    const Eigen::Vector3d X(l.x(), 0, 0), Y(0, l.y(), 0), Z(0, 0, l.z());
    rectangle(o, Y, X);
    rectangle(o + Z, X, Y);
    rectangle(o, X, Z);
    rectangle(o + Y, Z, X);
    rectangle(o, Z, Y);
    rectangle(o + X, Y, Z);
  }

  /// The sphere of radius r about c: one point per cell of unit area in (z, angle).
  void sphere(const Eigen::Vector3d& c, double r) {
    const int bands = std::max(2, static_cast<int>(std::lround(2.0 * r)));  // along z: 2r
    const int around = std::max(3, static_cast<int>(std::lround(2.0 * std::numbers::pi * r)));
    for (int i = 0; i < bands; ++i) {
      for (int j = 0; j < around; ++j) {
        const double z = -1.0 + 2.0 * (i + uniform()) / bands;  // area-uniform (Archimedes)
        const double t = 2.0 * std::numbers::pi * (j + uniform()) / around;
        const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
        const Eigen::Vector3d n(s * std::cos(t), s * std::sin(t), z);
        add(c + r * n, n);
      }
    }
  }

  /// A closed disc (coin) of radius R and thickness t about the origin, axis z.
  void coin(double R, double t) {
    for (const double side : {-1.0, 1.0}) {
      const int cells = static_cast<int>(std::lround(2.0 * R));
      for (int i = 0; i < cells; ++i) {
        for (int j = 0; j < cells; ++j) {
          const double x = -R + 2.0 * R * (i + uniform()) / cells;
          const double y = -R + 2.0 * R * (j + uniform()) / cells;
          if (x * x + y * y <= R * R) add({x, y, 0.5 * side * t}, {0, 0, side});
        }
      }
    }
    const int around = static_cast<int>(std::lround(2.0 * std::numbers::pi * R));
    const int up = std::max(1, static_cast<int>(std::lround(t)));
    for (int i = 0; i < around; ++i) {
      for (int j = 0; j < up; ++j) {
        const double a = 2.0 * std::numbers::pi * (i + uniform()) / around;
        const double z = -0.5 * t + t * (j + uniform()) / up;
        add({R * std::cos(a), R * std::sin(a), z}, {std::cos(a), std::sin(a), 0});
      }
    }
  }

  /// A torus (ring) of major radius R and tube radius r, axis z, sampled by area (rejection).
  void ring(double R, double r) {
    const int nu = static_cast<int>(std::lround(2.0 * std::numbers::pi * (R + r)));
    const int nv = std::max(3, static_cast<int>(std::lround(2.0 * std::numbers::pi * r)));
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const double u = 2.0 * std::numbers::pi * (i + uniform()) / nu;
        const double v = 2.0 * std::numbers::pi * (j + uniform()) / nv;
        if (uniform() * (R + r) > R + r * std::cos(v)) continue;
        const Eigen::Vector3d n(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
        add({(R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u),
             r * std::sin(v)},
            n);
      }
    }
  }

  /// The points so far, with Gaussian noise of standard deviation `noise` per coordinate.
  Solid take(double noise = 0.0) {
    Solid s;
    s.V.resize(static_cast<Eigen::Index>(points_.size()), 3);
    s.N.resize(s.V.rows(), 3);
    std::normal_distribution<double> g(0.0, 1.0);
    for (Eigen::Index i = 0; i < s.V.rows(); ++i) {
      Eigen::Vector3d p = points_[static_cast<std::size_t>(i)];
      if (noise > 0.0) p += noise * Eigen::Vector3d(g(rng_), g(rng_), g(rng_));
      s.V.row(i) = p.transpose();
      s.N.row(i) = normals_[static_cast<std::size_t>(i)].transpose();
    }
    return s;
  }

 private:
  std::mt19937_64 rng_;
  std::vector<Eigen::Vector3d> points_, normals_;
};

/// Points whose estimated normal is not on the truth's side (NaN counts as flipped).
inline int flipped_against(const RowMatrixX3d& N, const RowMatrixX3d& truth) {
  int count = 0;
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const double d = N.row(i).dot(truth.row(i));
    count += !(d > 0.0) ? 1 : 0;
  }
  return count;
}

}  // namespace focal::test
