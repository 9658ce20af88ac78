#pragma once
/// \file cloud_samples.h
/// Point clouds sampled from the analytic surfaces (surfaces.h) with their exact truth: the
/// test and benchmark inputs of the cloud estimators (docs/POINTS.md).
///
/// The samples are the vertices of the irregular triangulation (Poisson-disk samples of uniform
/// density over the area) without its faces, then, in this order:
///  1. position noise and normal noise exactly as add_position_noise / add_normal_noise (the
///     amplitude of position noise is relative to the mean spacing of the triangulation's edges);
///  2. graded density: a point at normalised height t in [0, 1] along x of the bounding box is
///     kept with probability 1 - graded * t (graded in [0, 1)), from a sample made
///     1 / (1 - graded / 2) times denser so that about `points` remain;
///  3. outliers: that fraction of the points, chosen at random, moved to uniform random
///     positions in the bounding box grown by 10% (their truth is NaN: they are on no surface);
///  4. normals dropped when `normals` is false.
/// Random numbers from std::mt19937_64 seeded by `surface.seed` (+1 to +4 per step).
#include "focal/surfaces/surfaces.h"

namespace focal {

struct CloudSampleOptions {
  /// kind, shape parameters, seed, and target_vertices: the approximate point count.
  /// The triangulation field is ignored (always irregular samples).
  SurfaceOptions surface{};
  double position_noise = 0.0;  ///< x mean edge length of the triangulation (paper: 0.1)
  double normal_noise = 0.0;    ///< n' = normalize(n + u), u uniform in [-a, a]^3 (paper: 0.05)
  double graded = 0.0;          ///< density falls by this fraction along x; [0, 1)
  double outliers = 0.0;        ///< fraction of points moved off the surface; [0, 1)
  bool normals = true;          ///< keep the exact (or noisy) normals
};

/// The cloud (AnalyticSurface::mesh has no faces) with its exact truth per point (NaN rows for
/// outliers; uv of outliers NaN too).
/// \throw InvalidInput as make_surface, or for options out of range.
[[nodiscard]] AnalyticSurface sample_cloud(const CloudSampleOptions& options);

}  // namespace focal
