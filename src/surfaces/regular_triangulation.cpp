// Regular triangulations of a parameter domain, and the domain statistics both kinds use.
#include <cmath>

#include "focal/core/error.h"
#include "surfaces/triangulation.h"

namespace focal::detail {

using Eigen::Vector2d;

bool in_domain(const ParameterDomain& d, const Vector2d& uv) {
  return !d.disc || uv.squaredNorm() <= d.u_max * d.u_max;
}

DomainStats domain_stats(const Parametrisation& s, const ParameterDomain& d) {
  constexpr int kSamples = 128;
  const double du = (d.u_max - d.u_min) / kSamples, dv = (d.v_max - d.v_min) / kSamples;
  DomainStats out;
  for (int i = 0; i < kSamples; ++i) {
    for (int j = 0; j < kSamples; ++j) {
      const Vector2d uv(d.u_min + (i + 0.5) * du, d.v_min + (j + 0.5) * dv);
      if (!in_domain(d, uv)) continue;
      const Derivatives x = s.derivatives(uv.x(), uv.y());
      const double element = x.xu.cross(x.xv).norm();
      out.area += element * du * dv;
      out.max_area_element = std::max(out.max_area_element, element);
      out.log_aspect +=
          element * du * dv *
          std::log(x.xu.norm() * (d.u_max - d.u_min) / (x.xv.norm() * (d.v_max - d.v_min)));
      const SurfacePoint p = point_from_derivatives(x);
      out.max_curvature = std::max({out.max_curvature, std::abs(p.k1), std::abs(p.k2)});
    }
  }
  out.log_aspect /= out.area;
  return out;
}

int effective_target(const DomainStats& stats, int target) {
  if (stats.max_curvature <= 0.0) return target;
  const double spacing = kMaxSpacingCurvature / stats.max_curvature;
  const double needed = std::ceil(kPacking * stats.area / (spacing * spacing));
  if (needed > kMaxTarget) {
    throw InvalidInput(
        "make_surface: the shape parameters need " + std::to_string(needed) +
        " vertices to be followed (spacing 0.8 / max |curvature|), above the limit " +
        std::to_string(kMaxTarget));
  }
  return std::max(target, static_cast<int>(needed));
}

namespace {

int grid_vertex_count(const ParameterDomain& d, int nu, int nv) {
  const int columns = d.periodic_v ? nv : nv + 1;
  if (d.poles) return 2 + (nu - 1) * columns;
  return (d.periodic_u ? nu : nu + 1) * columns;
}

/// Intervals (nu, nv) closest to `target` vertices with cells close to square in space.
std::pair<int, int> grid_size(const ParameterDomain& d, int target, double log_aspect) {
  const int min_u = d.periodic_u ? 3 : (d.poles ? 2 : 1);
  const int min_v = d.periodic_v ? 3 : 1;
  const int max_u = 4 * static_cast<int>(std::sqrt(target * std::exp(std::abs(log_aspect)))) + 8;
  std::pair<int, int> best{min_u, min_v};
  double best_score = 1e300;
  for (int nu = min_u; nu <= max_u; ++nu) {
    const int guess = std::max(min_v, target / nu);
    for (int nv = std::max(min_v, guess - 2); nv <= guess + 2; ++nv) {
      const double count = grid_vertex_count(d, nu, nv);
      const double score = std::abs(std::log(count / target)) +
                           0.5 * std::abs(std::log(static_cast<double>(nu) / nv) - log_aspect);
      if (score < best_score) {
        best_score = score;
        best = {nu, nv};
      }
    }
  }
  return best;
}

void add_triangle(std::vector<Face>& faces, int a, int b, int c) {
  if (a != b && b != c && c != a) faces.push_back({a, b, c});
}

}  // namespace

Triangulated regular_grid(const ParameterDomain& d, int target, double log_aspect) {
  // Plain ints, not a structured binding: the lambda below captures them, which clang before 16
  // rejects for bindings (the fuzz build uses clang 14).
  const std::pair<int, int> size = grid_size(d, target, log_aspect);
  const int nu = size.first, nv = size.second;
  const int columns = d.periodic_v ? nv : nv + 1;
  const int rows = d.periodic_u ? nu : nu + 1;
  const double du = (d.u_max - d.u_min) / nu, dv = (d.v_max - d.v_min) / nv;
  Triangulated t;
  const int last_row = d.poles ? nu - 1 : rows - 1;
  if (d.poles) t.uv.emplace_back(d.u_min, 0.0);
  for (int i = d.poles ? 1 : 0; i <= last_row; ++i) {
    for (int j = 0; j < columns; ++j) t.uv.emplace_back(d.u_min + i * du, d.v_min + j * dv);
  }
  if (d.poles) t.uv.emplace_back(d.u_max, 0.0);
  const int south = static_cast<int>(t.uv.size()) - 1;
  const auto index = [&](int i, int j) {
    const int jj = d.periodic_v ? j % nv : j;
    if (d.poles) return i == 0 ? 0 : (i == nu ? south : 1 + (i - 1) * columns + jj);
    return (d.periodic_u ? i % nu : i) * columns + jj;
  };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const int p00 = index(i, j), p10 = index(i + 1, j);
      const int p11 = index(i + 1, j + 1), p01 = index(i, j + 1);
      add_triangle(t.faces, p00, p10, p11);
      add_triangle(t.faces, p00, p11, p01);
    }
  }
  return t;
}

Triangulated regular_disc(double radius, int target) {
  const int m = std::max(
      1, static_cast<int>(std::lround((-3.0 + std::sqrt(9.0 + 12.0 * (target - 1))) / 6.0)));
  Triangulated t;
  t.uv.emplace_back(0.0, 0.0);
  for (int k = 1; k <= m; ++k) {
    for (int j = 0; j < 6 * k; ++j) {
      const double angle = 2.0 * kPi * j / (6 * k);
      t.uv.push_back(radius * k / m * Vector2d(std::cos(angle), std::sin(angle)));
    }
  }
  const auto start = [](int k) { return k == 0 ? 0 : 1 + 3 * k * (k - 1); };
  for (int k = 1; k <= m; ++k) {
    const int ni = std::max(1, 6 * (k - 1)), no = 6 * k;
    const auto inner = [&](int i) { return start(k - 1) + i % ni; };
    const auto outer = [&](int o) { return start(k) + o % no; };
    int i = 0, o = 0;
    while (i < ni || o < no) {
      // Advance on the ring whose next vertex comes first in angle; k = 1 is a fan.
      const bool step_outer = k == 1 || i == ni || (o < no && (o + 1) * ni <= (i + 1) * no);
      if (step_outer) {
        add_triangle(t.faces, inner(i), outer(o), outer(o + 1));
        ++o;
        if (k == 1 && o == no) i = ni;
      } else {
        add_triangle(t.faces, inner(i), outer(o), inner(i + 1));
        ++i;
      }
    }
  }
  return t;
}

}  // namespace focal::detail
