#include "focal/surfaces/cloud_samples.h"

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "surfaces/surface_model.h"

namespace focal {
namespace {

void validate(const CloudSampleOptions& o) {
  const auto fraction = [](double x) { return x >= 0.0 && x < 1.0; };
  if (!fraction(o.graded)) throw InvalidInput("sample_cloud: graded must be in [0, 1)");
  if (!fraction(o.outliers)) throw InvalidInput("sample_cloud: outliers must be in [0, 1)");
}

/// The rows of every per-point array of s listed in `keep`, in that order.
AnalyticSurface select_rows(const AnalyticSurface& s, const std::vector<int>& keep) {
  AnalyticSurface out;
  const auto n = static_cast<Eigen::Index>(keep.size());
  out.mesh.V.resize(n, 3), out.mesh.N.resize(s.mesh.N.rows() > 0 ? n : 0, 3);
  out.k1.resize(n), out.k2.resize(n), out.d1.resize(n, 3), out.d2.resize(n, 3), out.uv.resize(n, 2);
  for (Eigen::Index r = 0; r < n; ++r) {
    const int i = keep[static_cast<std::size_t>(r)];
    out.mesh.V.row(r) = s.mesh.V.row(i);
    if (out.mesh.N.rows() > 0) out.mesh.N.row(r) = s.mesh.N.row(i);
    out.k1[r] = s.k1[i], out.k2[r] = s.k2[i];
    out.d1.row(r) = s.d1.row(i), out.d2.row(r) = s.d2.row(i), out.uv.row(r) = s.uv.row(i);
  }
  out.mesh.F.resize(0, 3);
  return out;
}

std::vector<int> graded_rows(const RowMatrixX3d& V, double graded, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const double lo = V.col(0).minCoeff(), hi = V.col(0).maxCoeff();
  std::vector<int> keep;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const double t = hi > lo ? (V(i, 0) - lo) / (hi - lo) : 0.0;
    if (detail::uniform01(rng) < 1.0 - graded * t) keep.push_back(static_cast<int>(i));
  }
  return keep;
}

void add_outliers(AnalyticSurface& s, double fraction, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const Eigen::RowVector3d lo = s.mesh.V.colwise().minCoeff(), hi = s.mesh.V.colwise().maxCoeff();
  const Eigen::RowVector3d margin = 0.1 * (hi - lo);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
    if (detail::uniform01(rng) >= fraction) continue;
    for (int c = 0; c < 3; ++c) {
      s.mesh.V(i, c) = detail::uniform(rng, lo[c] - margin[c], hi[c] + margin[c]);
    }
    s.k1[i] = s.k2[i] = nan;
    s.d1.row(i).setConstant(nan), s.d2.row(i).setConstant(nan), s.uv.row(i).setConstant(nan);
  }
}

}  // namespace

AnalyticSurface sample_cloud(const CloudSampleOptions& options) {
  validate(options);
  SurfaceOptions surface = options.surface;
  surface.triangulation = Triangulation::irregular;
  const std::uint64_t seed = surface.seed;
  surface.target_vertices =
      static_cast<int>(std::lround(surface.target_vertices / (1.0 - 0.5 * options.graded)));
  AnalyticSurface s = make_surface(surface);
  if (options.position_noise > 0) add_position_noise(s.mesh, options.position_noise, seed + 1);
  if (options.normal_noise > 0) add_normal_noise(s.mesh, options.normal_noise, seed + 2);
  std::vector<int> keep(static_cast<std::size_t>(s.mesh.V.rows()));
  for (std::size_t i = 0; i < keep.size(); ++i) keep[i] = static_cast<int>(i);
  if (options.graded > 0) keep = graded_rows(s.mesh.V, options.graded, seed + 3);
  AnalyticSurface cloud = select_rows(s, keep);
  if (options.outliers > 0) add_outliers(cloud, options.outliers, seed + 4);
  if (!options.normals) cloud.mesh.N.resize(0, 3);
  return cloud;
}

}  // namespace focal
