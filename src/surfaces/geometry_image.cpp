// Geometry images of the analytic surfaces: the exact surface sampled on a parameter grid.
#include "focal/surfaces/geometry_image.h"

#include <cmath>
#include <limits>
#include <string>

#include "core/parallel.h"
#include "focal/core/error.h"

namespace focal {
namespace {

constexpr int kMaxSide = 16384;

void store(std::vector<float>& v, std::size_t i, const Eigen::Vector3d& value) {
  for (int c = 0; c < 3; ++c) v[3 * i + c] = static_cast<float>(value[c]);
}

/// A pixel outside a disc domain: an empty G-buffer pixel (zeros, as a cleared render target)
/// and no truth.
void store_uncovered(GeometryImage& g, std::size_t i) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int c = 0; c < 3; ++c) {
    g.gbuffer.position[3 * i + c] = g.gbuffer.normal[3 * i + c] = 0.0f;
    g.d1[3 * i + c] = g.d2[3 * i + c] = nan;
  }
  g.gbuffer.mask[i] = 0;
  g.k1[i] = g.k2[i] = nan;
}

void store_covered(GeometryImage& g, std::size_t i, const SurfacePoint& p) {
  store(g.gbuffer.position, i, p.position);
  store(g.gbuffer.normal, i, p.normal);
  store(g.d1, i, p.d1);
  store(g.d2, i, p.d2);
  g.gbuffer.mask[i] = 1;
  g.k1[i] = static_cast<float>(p.k1);
  g.k2[i] = static_cast<float>(p.k2);
}

GeometryImage allocated(int width, int height) {
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  GeometryImage g;
  g.gbuffer.width = width;
  g.gbuffer.height = height;
  g.gbuffer.position.resize(3 * n);
  g.gbuffer.normal.resize(3 * n);
  g.gbuffer.mask.resize(n);
  g.k1.resize(n);
  g.k2.resize(n);
  g.d1.resize(3 * n);
  g.d2.resize(3 * n);
  return g;
}

}  // namespace

GeometryImage geometry_image(const SurfaceOptions& surface, int width, int height) {
  if (width < 2 || height < 2 || width > kMaxSide || height > kMaxSide) {
    throw InvalidInput("geometry_image: size " + std::to_string(width) + " x " +
                       std::to_string(height) + " outside [2, " + std::to_string(kMaxSide) +
                       "] per side");
  }
  const ParameterDomain d = surface_domain(surface);  // throws for invalid shape parameters
  const double du = (d.u_max - d.u_min) / width, dv = (d.v_max - d.v_min) / height;
  GeometryImage g = allocated(width, height);
  detail::parallel_for(static_cast<std::int64_t>(width) * height, 0, [&](std::int64_t i) {
    const double u = d.u_min + (static_cast<double>(i % width) + 0.5) * du;
    const double v = d.v_min + (static_cast<double>(i / width) + 0.5) * dv;
    const auto at = static_cast<std::size_t>(i);
    if (d.disc && u * u + v * v > d.u_max * d.u_max) {
      store_uncovered(g, at);
    } else {
      store_covered(g, at, evaluate_surface(surface, u, v));
    }
  });
  return g;
}

}  // namespace focal
