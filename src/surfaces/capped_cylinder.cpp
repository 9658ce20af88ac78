// The capped cylinder: a piecewise-smooth surface with two sharp rims (surfaces.h).
#include <cmath>
#include <string>

#include "focal/core/error.h"
#include "surfaces/triangulation.h"

namespace focal {
namespace {

using detail::Face;
using detail::kPi;
using Eigen::Vector3d;

/// Vertices of a cap of m rings (regular_disc) and of the whole capped cylinder for it.
int disc_vertices(int m) { return 1 + 3 * m * (m + 1); }
int side_rows(double radius, double height, int m) {
  // Rows spaced like the columns (2 pi radius / 6m), so that side cells are close to square.
  return std::max(1, static_cast<int>(std::lround(height * 6 * m / (2.0 * kPi * radius))));
}
int capped_vertices(double radius, double height, int m) {
  return 2 * disc_vertices(m) + (side_rows(radius, height, m) - 1) * 6 * m;
}

/// The ring count whose vertex count is closest to target (in ratio).
int rings_for(double radius, double height, int target) {
  int best = 1;
  for (int m = 1; capped_vertices(radius, height, m) < 4 * target; ++m) {
    const auto error = [&](int k) {
      return std::abs(std::log(static_cast<double>(capped_vertices(radius, height, k)) / target));
    };
    if (error(m) < error(best)) best = m;
  }
  return best;
}

struct Truth {
  Vector3d x, n, d1;
  double k1;
  bool crease;
};

}  // namespace

AnalyticSurface make_capped_cylinder(double radius, double height, int target_vertices) {
  if (!(radius > 0.0) || !std::isfinite(radius) || !(height > 0.0) || !std::isfinite(height)) {
    throw InvalidInput("make_capped_cylinder: radius and height must be finite and > 0");
  }
  if (target_vertices < 16 || target_vertices > detail::kMaxTarget) {
    throw InvalidInput("make_capped_cylinder: target_vertices must be in [16, " +
                       std::to_string(detail::kMaxTarget) + "], got " +
                       std::to_string(target_vertices));
  }
  const int m = rings_for(radius, height, target_vertices);
  const int rows = side_rows(radius, height, m), columns = 6 * m;
  const detail::Triangulated disc = detail::regular_disc(radius, disc_vertices(m));
  const int cap = static_cast<int>(disc.uv.size());
  const int rim = cap - columns;  // the outer ring's first index in a cap
  std::vector<Truth> vertices;
  std::vector<Face> faces;
  const Vector3d up(0, 0, 1);
  const auto side_point = [&](double angle, double z, bool crease, double cap_side) {
    const Vector3d n(std::cos(angle), std::sin(angle), 0.0);
    const Vector3d normal = crease ? (n + cap_side * up).normalized() : n;
    return Truth{Vector3d(radius * n.x(), radius * n.y(), z), normal, up.cross(n), 1.0 / radius,
                 crease};
  };
  // Caps: top (normal +z) then bottom (normal -z, triangles reversed); the outer rings are the
  // rims, shared with the side.
  for (const double cap_side : {1.0, -1.0}) {
    const int offset = static_cast<int>(vertices.size());
    for (int i = 0; i < cap; ++i) {
      if (i >= rim) {
        vertices.push_back(
            side_point(2.0 * kPi * (i - rim) / columns, cap_side * 0.5 * height, true, cap_side));
      } else {
        const Eigen::Vector2d p = disc.uv[static_cast<std::size_t>(i)];
        vertices.push_back({Vector3d(p.x(), p.y(), cap_side * 0.5 * height), cap_side * up,
                            Vector3d(1, 0, 0), 0.0, false});
      }
    }
    for (const Face& f : disc.faces) {
      faces.push_back(cap_side > 0 ? Face{offset + f[0], offset + f[1], offset + f[2]}
                                   : Face{offset + f[0], offset + f[2], offset + f[1]});
    }
  }
  const int interior = static_cast<int>(vertices.size());
  for (int j = 1; j < rows; ++j) {
    for (int c = 0; c < columns; ++c) {
      vertices.push_back(
          side_point(2.0 * kPi * c / columns, -0.5 * height + height * j / rows, false, 0.0));
    }
  }
  const auto side_index = [&](int c, int j) {
    c %= columns;
    if (j == 0) return cap + rim + c;  // bottom rim
    if (j == rows) return rim + c;     // top rim
    return interior + (j - 1) * columns + c;
  };
  for (int j = 0; j < rows; ++j) {
    for (int c = 0; c < columns; ++c) {
      faces.push_back({side_index(c, j), side_index(c + 1, j), side_index(c + 1, j + 1)});
      faces.push_back({side_index(c, j), side_index(c + 1, j + 1), side_index(c, j + 1)});
    }
  }
  AnalyticSurface out;
  const auto n = static_cast<Eigen::Index>(vertices.size());
  out.mesh.V.resize(n, 3);
  out.mesh.N.resize(n, 3);
  out.d1.resize(n, 3);
  out.d2.resize(n, 3);
  out.k1.resize(n);
  out.k2 = Eigen::VectorXd::Zero(n);
  out.uv.resize(n, 2);
  out.crease.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Truth& t = vertices[static_cast<std::size_t>(i)];
    out.mesh.V.row(i) = t.x.transpose();
    out.mesh.N.row(i) = t.n.transpose();
    out.d1.row(i) = t.d1.transpose();
    // The smooth piece's normal (not the crease's mean) completes the right-handed frame.
    const Vector3d piece_normal = t.k1 > 0.0 ? Vector3d(t.x.x(), t.x.y(), 0.0).normalized() : t.n;
    out.d2.row(i) = piece_normal.cross(t.d1).transpose();
    out.k1[i] = t.k1;
    out.uv.row(i) = Eigen::Vector2d(std::atan2(t.x.y(), t.x.x()), t.x.z()).transpose();
    out.crease[i] = t.crease ? 1 : 0;
  }
  out.mesh.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    for (int c = 0; c < 3; ++c) out.mesh.F(static_cast<Eigen::Index>(f), c) = faces[f][c];
  }
  const auto nf = static_cast<int>(faces.size());
  out.mesh.face_source = Eigen::VectorXi::LinSpaced(nf, 0, nf - 1);
  return out;
}

}  // namespace focal
