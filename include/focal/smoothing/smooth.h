#pragma once
/// \file smooth.h
/// Denoising meshes and point clouds onto the smooth surface around each point: every vertex is
/// moved, along its normal, onto the height polynomial (a quadric: the osculating jet of degree
/// 2, normals/jets.h) fitted over its neighbourhood in the frame of its normal, the
/// neighbourhood as wide as the measured position noise asks (the recommended estimator's
/// rings, focal/curvature/recommended.h; on clouds the cloud default's nearest neighbours), and
/// the whole repeated in the frame of the fitted normals until the measured noise stops
/// falling. Moving onto a fitted quadric rather than towards the neighbours' mean keeps
/// curved surfaces where they are: a sphere keeps its radius (to the fit's truncation error,
/// O(h^4) per step), where Laplacian smoothing shrinks it. Each fit is robust: points far off
/// the surface of the others (spikes, outliers) are left out of it and are themselves moved back
/// onto it. With `keep_creases`, a point whose neighbours' normals fall into two groups more
/// than `crease_angle` apart is fitted to its own side only, or, lying between the two, moved
/// onto the line where the two sides' surfaces meet. Boundary vertices move along their normal
/// only, like all others, so a boundary does not shrink inwards.
///
/// Deterministic for any thread count; rows and connectivity are kept (the result has a row
/// per input row, in input order). Method and measurements: docs/SMOOTH.md.

#include <vector>

#include "focal/core/execution.h"
#include "focal/core/fields.h"
#include "focal/core/mesh.h"
#include "focal/mesh/prepared.h"

namespace focal {

/// The most iterations the automatic stop runs (SmoothOptions::iterations = 0).
inline constexpr int kMaxSmoothIterations = 10;

struct SmoothOptions {
  /// Passes over all points. 0: until the measured position noise (the fits' median residual)
  /// falls by less than `min_noise_fall` from one pass to the next, at most
  /// kMaxSmoothIterations; a pass that does not lower it is not kept (a clean mesh is returned
  /// as it is, but for its spikes). > 0: exactly this many passes.
  int iterations = 0;
  /// With iterations = 0: a pass is kept while it lowers the measured noise to at most this
  /// fraction of the previous pass's.
  double min_noise_fall = 0.9;
  /// Meshes: rings of each fit; 0 chooses from the position noise (2 on clean or slightly
  /// noisy meshes, the recommended estimator's jet rings, 3 or 4, on noisy ones).
  int rings = 0;
  /// Clouds: nearest neighbours of each fit; 0 chooses from the position noise (16, or 64 above
  /// the cloud default's noise threshold of 0.03 mean spacings).
  int neighbours = 0;
  /// Degree of the fitted height polynomial, 1 to 4 (1: planes, which flatten curved
  /// surfaces; 2: quadrics).
  int degree = 2;
  /// Leave out of each fit the points far off the others' surface (and move them back).
  bool robust = true;
  /// Fit each side of a sharp crease separately and keep the points on it on both sides'
  /// intersection.
  bool keep_creases = false;
  /// Radians: neighbours' normals in two groups more than this apart make a crease.
  double crease_angle = 1.0471975511965976;  // 60 degrees
  /// Threads, progress ("smooth" per pass), warnings, cancellation.
  Execution execution{};
};

struct SmoothResult {
  RowMatrixX3d V;  ///< #V x 3 smoothed positions (rows that could not be fitted are the input's)
  /// #V x 3 unit normals of the fitted surfaces at the smoothed positions (NaN rows where no fit
  /// was possible), on the side of the input's normals when it has them, else of its faces (on
  /// clouds: of the outward-oriented cloud normals, normals/cloud_normals.h).
  RowMatrixX3d N;
  int iterations = 0;  ///< passes kept
  /// Measured position noise (median fit residual, in mean edge lengths or mean spacings) of
  /// the input and after each kept pass: noise.size() == iterations + 1.
  std::vector<double> noise;
  int rings = 0;       ///< meshes: rings of the fits
  int neighbours = 0;  ///< clouds: neighbours of the fits
  /// Points that were far off their neighbours' surface in the first pass (spikes, outliers):
  /// moved back onto it even when no pass is kept.
  int outliers_moved = 0;
  int crease_points = 0;  ///< points kept on several sides of a crease (keep_creases)
  /// #V flags, 1 at those points (in the pass that gave the result; all 0 without keep_creases).
  VectorXu8 crease;
  int unfitted = 0;  ///< points left where they were: no well-posed fit
};

/// Smooths a mesh (or, when it has no faces, a point cloud) as described above.
/// \throw InvalidInput when an option is out of range; Cancelled when execution.cancel is set.
[[nodiscard]] SmoothResult smooth(const PreparedMesh& mesh, const SmoothOptions& options = {});

/// smooth() of a read mesh or cloud (io/mesh_io.h).
[[nodiscard]] SmoothResult smooth(const Mesh& mesh, const SmoothOptions& options = {});

}  // namespace focal
