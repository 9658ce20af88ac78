#pragma once
// Internal: the smooth surface fitted around one point (smoothing/surface_fit.cpp) for
// smoothing/smooth.cpp: a height polynomial (the jets' fit, normals/jet_fit.h) over the point's
// neighbourhood in the frame of its normal, refitted without the points far off it, and the
// surface's point and normal above the point's own position.

#include <Eigen/Core>
#include <vector>

#include "focal/core/mesh.h"
#include "normals/jet_fit.h"
#include "normals/jet_points.h"

namespace focal::detail::smoothing {

/// The surface fitted around one point.
struct LocalSurface {
  Eigen::Vector3d point =
      Eigen::Vector3d::Zero();  ///< the fitted graph's point over (0, 0): P + height * n
  Eigen::Vector3d normal =
      Eigen::Vector3d::Zero();   ///< its unit normal there, on the frame normal's side
  double height = 0.0;           ///< signed offset from P to `point` along the frame normal
  double residual = 0.0;         ///< RMS height residual of the kept points (length units)
  int kept = 0;                  ///< points in the final fit
  bool centre_rejected = false;  ///< the point itself lay far off the surface of the others
  /// false: no well-posed fit (too few points, degenerate, or a point beyond the
  /// neighbourhood's radius)
  bool ok = false;
};

/// A thread's scratch, reused across fits.
struct FitScratch {
  jets::Points points, kept_points;
  std::vector<double> terms;
  std::vector<double> misfit, saved_misfit;
  std::vector<char> keep;
  jets::JetBatch batch;
};

/// Residuals beyond this many robust scales (1.4826 x the median absolute residual) are outliers:
/// 1D Gaussian residuals pass it with probability 1 - 6e-7, so clean data keep every point.
inline constexpr double kOutlierScales = 5.0;
/// Rounds of rejection after the trimmed start (each from all points).
inline constexpr int kRejectionRounds = 3;
/// A least-squares fit with a residual beyond this many robust scales starts the robust fit.
inline constexpr double kSuspectScales = 3.0;
/// The robust fit's start: kTrimSteps least-squares fits, each over this share of the points
/// nearest the previous fit (up to 25% outliers cannot bend it).
inline constexpr double kTrimmedShare = 0.75;
inline constexpr int kTrimSteps = 2;

/// The robust step (one function, to be swapped for another detector): flags in `keep` the
/// points whose |residual| is within kOutlierScales robust scales and at least `floor` (length
/// units in the fit's scaled coordinates: below it no point is an outlier, so that the
/// truncation error of a clean surface, which is not Gaussian, is never cut). Returns the
/// number of points rejected.
int reject_far_points(const std::vector<double>& misfit, double floor, std::vector<char>& keep);

/// The surface of `degree` (1 to jets::kMaxDegree) fitted around V.row(i) over the points
/// V.row(j) of `ring` (i itself may be listed; it is always in the fit, at the origin) in the
/// frame of the unit normal `n`. `robust`: where the least-squares fit has a point beyond
/// kSuspectScales, a trimmed start, then the points off it (reject_far_points with `floor` in
/// length units) left out and the fit repeated; elsewhere the least-squares fit.
LocalSurface fit_local_surface(PositionsRef V, int i, const Eigen::Vector3d& n,
                               const std::vector<int>& ring, int degree, bool robust, double floor,
                               FitScratch& s);

/// fit_local_surface at up to kMaxLanes points side by side, all of one degree: their
/// least-squares fits in the lanes of the jets' kernel (each lane with the bits of the scalar
/// fit), the rest point by point. Each result is fit_local_surface's, bit for bit.
struct LaneFits {
  LaneFits();
  const int width;  ///< the kernel's lanes
  int queued = 0;
  /// Gathers point i's fit (fit_local_surface's arguments) into the next lane; queued < width.
  void queue(PositionsRef V, int i, const Eigen::Vector3d& n, const std::vector<int>& ring);
  /// The queued fits of `degree` into out[0 .. queued); empties the queue.
  void run(PositionsRef V, int degree, bool robust, double floor, LocalSurface* out);

 private:
  FitScratch lane[jets::kMaxLanes];
  kernels::Frame<double> frame[jets::kMaxLanes];
  double scale[jets::kMaxLanes] = {};
  int point[jets::kMaxLanes] = {};
  jets::JetBatch batch;
  std::vector<double> terms;
  jets::Points zeros;
};

}  // namespace focal::detail::smoothing
