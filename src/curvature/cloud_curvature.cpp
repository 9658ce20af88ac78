#include "focal/curvature/cloud_curvature.h"

#include <string>
#include <utility>
#include <vector>

#include "curvature/curvature_detail.h"
#include "focal/core/error.h"
#include "focal/points/neighbours.h"
#include "mesh/prepared_detail.h"

namespace focal {
namespace {

/// Radius neighbourhoods keep at most this many (the nearest): a radius far larger than the
/// spacing would otherwise make the lists, and the fit, quadratic in the density.
constexpr int kMaxRadiusNeighbours = 1024;

void validate(PositionsRef V, std::optional<NormalsRef> N, const CloudOptions& o) {
  if (o.k < 0) throw InvalidInput("cloud curvature: k must be >= 0, got " + std::to_string(o.k));
  if (!(o.radius >= 0.0)) throw InvalidInput("cloud curvature: radius must be >= 0");
  if (o.threads < 0) throw InvalidInput("cloud curvature: threads must be >= 0");
  if (N && N->rows() != V.rows()) {
    throw InvalidInput("cloud curvature: " + std::to_string(N->rows()) + " normals for " +
                       std::to_string(V.rows()) + " points");
  }
}

}  // namespace

Neighbourhoods cloud_neighbourhoods(PositionsRef V, const CloudOptions& options) {
  if (options.k < 0 || !(options.radius >= 0.0) || options.threads < 0) {
    throw InvalidInput("cloud neighbourhoods: k, radius and threads must be >= 0");
  }
  if (options.radius > 0.0) {
    return radius_neighbours(V, options.radius, kMaxRadiusNeighbours, options.threads);
  }
  const int k = options.k > 0 ? options.k : default_cloud_neighbours;
  return nearest_neighbours(V, k, options.threads);
}

CloudCurvature estimate_cloud_curvature(PositionsRef V, std::optional<NormalsRef> N,
                                        const CloudOptions& options) {
  validate(V, N, options);
  CloudCurvature out;
  out.neighbours = cloud_neighbourhoods(V, options);
  out.spacing = mean_spacing(V, out.neighbours);
  if (N) {
    out.N = *N;
  } else {
    CloudNormalOptions normals = options.normals;
    normals.threads = options.threads;
    out.N = cloud_normals(V, out.neighbours, normals);
    out.normals_estimated = true;
  }
  std::vector<char> ok;
  out.N = detail::unit_rows(out.N, ok, options.threads);
  CurvatureOptions fit;
  fit.solver = options.solver;
  fit.levenberg_marquardt = options.levenberg_marquardt;
  fit.zero_tolerance = options.zero_tolerance;
  fit.umbilic_tolerance = options.umbilic_tolerance;
  fit.threads = options.threads;
  detail::validate_curvature_options(fit);
  // A spacing of 0 (a single point, or all duplicates) would make every |k| "not zero"; 1 keeps
  // the tolerance finite, and such points are undefined anyway (fewer than two rays).
  const double scale = out.spacing > 0.0 ? out.spacing : 1.0;
  out.curvature = detail::fit_vertices({V, out.N, ok, out.neighbours, scale}, fit);
  return out;
}

}  // namespace focal
