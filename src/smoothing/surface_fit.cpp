// The robust local surface of smoothing/surface_fit.h.
#include "smoothing/surface_fit.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "core/simd_lanes.h"
#include "kernels/eigen.h"
#include "kernels/local_shape.h"

namespace focal::detail::smoothing {
namespace {

using jets::coefficient_count;
using jets::terms_stride;
using kernels::eigen_of;

/// Two doubles as one SSE2 register: two points' heights at once, each with the products and
/// sums of one alone (the same bits).
using Pair = double __attribute__((vector_size(2 * sizeof(double))));

/// The fitted height at scaled coordinates (x, y): sum c_k x^(t-b) y^b over the monomials
/// by degree t, then by the power b of y (jet_fit.cpp's numbering). D fixed: unrolled, the same
/// operations in the same order for every D; T a double or a Pair.
template <int D, class T>
T height_at(const double* c, T x, T y) {
  T xs[D + 1], ys[D + 1];
  xs[0] = ys[0] = T{} + 1.0;
  for (int t = 1; t <= D; ++t) xs[t] = xs[t - 1] * x, ys[t] = ys[t - 1] * y;
  T height = T{};
  int k = 0;
  for (int t = 0; t <= D; ++t) {
    for (int b = 0; b <= t; ++b, ++k) height += c[k] * xs[t - b] * ys[b];
  }
  return height;
}

template <int D>
void misfits_of_degree(FitScratch& s) {
  const double* c = s.batch.c;
  const jets::Point* q = s.points.data();
  double* out = s.misfit.data();
  const std::size_t n = s.points.size();
  std::size_t p = 0;
  for (; p + 1 < n; p += 2) {
    const Pair x = {q[p].x, q[p + 1].x}, y = {q[p].y, q[p + 1].y}, z = {q[p].z, q[p + 1].z};
    const Pair r = z - height_at<D>(c, x, y);
    out[p] = r[0], out[p + 1] = r[1];
  }
  if (p < n) out[p] = q[p].z - height_at<D>(c, q[p].x, q[p].y);
}

/// The least-squares fit of `degree` to `points` (one lane of the scalar kernel) into s.batch.c.
/// False when the system is not well posed.
bool fit_points(int degree, const jets::Points& points, FitScratch& s) {
  jets::JetBatch& b = s.batch;
  const int n = static_cast<int>(points.size());
  b.points[0] = points.data();
  b.count[0] = b.points_max = n;
  s.terms.resize(static_cast<std::size_t>(n) * terms_stride(degree));
  b.terms = s.terms.data();
  jets::top_degree_kernel(std::nullopt, degree)(b);
  return b.solved[0];
}

/// Each point's residual against the fit in s.batch.c into s.misfit (scaled units).
void misfits(int degree, FitScratch& s) {
  s.misfit.resize(s.points.size());
  switch (degree) {
    case 4:
      return misfits_of_degree<4>(s);
    case 3:
      return misfits_of_degree<3>(s);
    case 2:
      return misfits_of_degree<2>(s);
    default:
      return misfits_of_degree<1>(s);
  }
}

/// The fitted height at the origin, as misfits() evaluates it for the point at (0, 0).
double height_at_origin(int degree, const double* c) {
  switch (degree) {
    case 4:
      return height_at<4>(c, 0.0, 0.0);
    case 3:
      return height_at<3>(c, 0.0, 0.0);
    case 2:
      return height_at<2>(c, 0.0, 0.0);
    default:
      return height_at<1>(c, 0.0, 0.0);
  }
}

/// Refits s.points flagged in s.keep; the residuals of all points against it into s.misfit.
bool fit_kept(int degree, FitScratch& s) {
  s.kept_points.clear();
  for (std::size_t p = 0; p < s.points.size(); ++p) {
    if (s.keep[p]) s.kept_points.push_back(s.points[p]);
  }
  // The origin (the point itself) may be gone: the fit is then of the others' surface.
  if (!fit_points(degree, s.kept_points, s)) return false;
  misfits(degree, s);
  return true;
}

/// Whether `value` exceeds both `floor` and `scales` robust scales (1.4826 x the median of
/// |r| over the n residuals r, the median the element at n / 2 in ascending order), without
/// ordering them: c x e is monotone in e, so c x median < value exactly where more than n / 2
/// of the |r| have c x |r| < value (the same decision as selecting the median, bit for bit).
bool beyond_robust_scales(const double* r, std::size_t n, double scales, double floor,
                          double value) {
  if (!(value > floor)) return false;
  const double c = scales * 1.4826;
  std::size_t below = 0;
  for (std::size_t p = 0; p < n; ++p) below += c * std::abs(r[p]) < value;
  return below > n / 2;
}

/// Whether a least-squares fit's residuals hint at outliers: one beyond kSuspectScales robust
/// scales (and the floor). Gaussian residuals pass it in most fits; a point far off, or two
/// that bend the fit towards them (masking each other), do not.
bool suspect(const std::vector<double>& misfit, double floor) {
  double largest = 0.0;
  for (const double r : misfit) largest = std::max(largest, std::abs(r));
  return beyond_robust_scales(misfit.data(), misfit.size(), kSuspectScales, floor, largest);
}

/// Whether the point itself (the origin) lies beyond kSuspectScales robust scales (and the
/// floor) off the surface of the others: a spike that bends the least-squares fit towards it
/// can leave every residual of that fit within bounds. s.batch.c and s.misfit stay the
/// least-squares fit's.
bool centre_off(int degree, double floor, FitScratch& s) {
  const int m = coefficient_count(degree);
  double c[jets::kMaxCoefficients];
  std::copy(s.batch.c, s.batch.c + m, c);
  // The fit without the point itself from the least-squares fit's moments: the point is the
  // origin, which adds 1 to the count and +0 to every other sum, so the sums without it are
  // those with 1 taken off the count (the bits of a fit to the others alone).
  jets::JetBatch& b = s.batch;
  const double count = b.xy[0];
  b.xy[0] = count - 1.0;
  bool off = false;
  const bool solved = jets::solve_moments(degree, b, b.count[0] - 1);
  b.xy[0] = count;
  // The point's own residual against that fit (misfits' value at the origin, the same bits):
  // within the floor it is no outlier, and the others' residuals need not be evaluated.
  if (solved && std::abs(0.0 - height_at_origin(degree, b.c)) > floor) {
    s.saved_misfit = s.misfit;
    misfits(degree, s);
    // The others' residuals alone set the scale.
    off = beyond_robust_scales(s.misfit.data() + 1, s.misfit.size() - 1, kSuspectScales, floor,
                               std::abs(s.misfit[0]));
    s.misfit.swap(s.saved_misfit);
  }
  std::copy(c, c + m, s.batch.c);
  s.keep.assign(s.points.size(), 1);
  return off;
}

/// A start that outliers do not bend: the fit without the point itself (at the origin), then
/// concentration steps of least trimmed squares (Rousseeuw and Van Driessen 2006), each fit
/// over the kTrimmedShare of the points nearest the previous one; the residuals of all points
/// against the last into s.misfit.
bool trimmed_start(int degree, FitScratch& s) {
  const std::size_t n = s.points.size();
  const std::size_t m = static_cast<std::size_t>(coefficient_count(degree));
  const std::size_t h = std::max(m + 1, static_cast<std::size_t>(kTrimmedShare * n));
  if (h >= n) return true;
  // The first concentration step starts from the others' surface: the point itself, the one
  // whose place is in question, out of it.
  s.keep.assign(n, 1);
  s.keep[0] = 0;
  if (!fit_kept(degree, s)) return false;
  std::vector<double> magnitude(n);
  for (int step = 0; step < kTrimSteps; ++step) {
    for (std::size_t p = 0; p < n; ++p) magnitude[p] = std::abs(s.misfit[p]);
    std::vector<double> sorted = magnitude;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(h - 1),
                     sorted.end());
    const double cut = sorted[h - 1];
    std::size_t taken = 0;
    for (std::size_t p = 0; p < n; ++p) {
      s.keep[p] = magnitude[p] < cut && taken < h;
      taken += s.keep[p];
    }
    for (std::size_t p = 0; p < n && taken < h; ++p) {
      if (!s.keep[p] && magnitude[p] == cut) s.keep[p] = 1, ++taken;
    }
    if (!fit_kept(degree, s)) return false;
  }
  return true;
}

}  // namespace

int reject_far_points(const std::vector<double>& misfit, double floor, std::vector<char>& keep) {
  std::vector<double> magnitude(misfit.size());
  for (std::size_t p = 0; p < misfit.size(); ++p) magnitude[p] = std::abs(misfit[p]);
  const auto middle = magnitude.begin() + static_cast<std::ptrdiff_t>(magnitude.size() / 2);
  std::nth_element(magnitude.begin(), middle, magnitude.end());
  const double cut = std::max(kOutlierScales * 1.4826 * *middle, floor);
  keep.assign(misfit.size(), 1);
  int rejected = 0;
  for (std::size_t p = 0; p < misfit.size(); ++p) {
    if (std::abs(misfit[p]) > cut) keep[p] = 0, ++rejected;
  }
  return rejected;
}

namespace {

/// The surface of the fit in s (its coefficients, the kept points' residuals) around V.row(i).
LocalSurface surface_of_fit(PositionsRef V, int i, const kernels::Frame<double>& frame,
                            double scale, int degree, const FitScratch& s) {
  LocalSurface out;
  const jets::JetBatch& b = s.batch;
  double ssr = 0.0;
  int kept = 0;
  for (std::size_t p = 0; p < s.points.size(); ++p) {
    if (s.keep[p]) ssr += s.misfit[p] * s.misfit[p], ++kept;
  }
  const int m = coefficient_count(degree);
  out.centre_rejected = !s.keep[0];
  out.kept = kept;
  out.residual = kept > m ? std::sqrt(ssr / (kept - m)) * scale : 0.0;
  out.height = b.c[0] * scale;
  const Eigen::Vector3d n = eigen_of(frame.n);
  out.point = V.row(i).transpose() + out.height * n;
  out.normal = (n - b.c[1] * eigen_of(frame.x) - b.c[2] * eigen_of(frame.y)).normalized();
  // A fitted point beyond the neighbourhood's radius is the extrapolation of an ill-posed fit
  // (points nearly on a curve after rejection), not a surface through them.
  out.ok =
      out.point.allFinite() && out.normal.allFinite() && std::abs(out.height) <= scale && kept > m;
  return out;
}

/// The robust refit of s.points from the least-squares fit in s: a trimmed start, then rounds
/// of rejection. False where a fit on the way is not well posed.
bool robust_refit(int degree, double scaled_floor, FitScratch& s) {
  if (!trimmed_start(degree, s)) return false;
  std::vector<char> previous(s.points.size(), 0);
  for (int round = 0; round < kRejectionRounds; ++round) {
    reject_far_points(s.misfit, scaled_floor, s.keep);
    if (s.keep == previous) break;
    if (!fit_kept(degree, s)) return false;
    previous = s.keep;
  }
  s.keep = previous;
  return true;
}

}  // namespace

namespace {

/// The rest of fit_local_surface after its least-squares fit (in s.batch, solved, over s.points
/// in `frame`, scaled by `scale`): the residuals, the test for outliers and the robust refit.
LocalSurface finish_fit(PositionsRef V, int i, const kernels::Frame<double>& frame, double scale,
                        int degree, bool robust, double floor, FitScratch& s) {
  misfits(degree, s);
  s.keep.assign(s.points.size(), 1);
  const double scaled_floor = floor / scale;
  if (!robust || !(suspect(s.misfit, scaled_floor) || centre_off(degree, scaled_floor, s))) {
    return surface_of_fit(V, i, frame, scale, degree, s);
  }
  // The least-squares fit, kept for where the robust one is not well posed.
  const int m = coefficient_count(degree);
  double c[jets::kMaxCoefficients];
  std::copy(s.batch.c, s.batch.c + m, c);
  s.saved_misfit = s.misfit;
  if (robust_refit(degree, scaled_floor, s)) {
    const LocalSurface out = surface_of_fit(V, i, frame, scale, degree, s);
    if (out.ok) return out;
  }
  std::copy(c, c + m, s.batch.c);
  s.misfit.swap(s.saved_misfit);
  s.keep.assign(s.points.size(), 1);
  return surface_of_fit(V, i, frame, scale, degree, s);
}

}  // namespace

LocalSurface fit_local_surface(PositionsRef V, int i, const Eigen::Vector3d& n,
                               const std::vector<int>& ring, int degree, bool robust, double floor,
                               FitScratch& s) {
  const kernels::Frame<double> frame = kernels::frame_of(kernels::vec3_of(n));
  const double scale = jets::gather_points(V, i, frame, ring, s.points);
  if (!(scale > 0.0) || !fit_points(degree, s.points, s)) return {};
  return finish_fit(V, i, frame, scale, degree, robust, floor, s);
}

LaneFits::LaneFits() : width(jets::batch_width(SimdIsa::best)) {}

void LaneFits::queue(PositionsRef V, int i, const Eigen::Vector3d& n,
                     const std::vector<int>& ring) {
  const int l = queued++;
  point[l] = i;
  frame[l] = kernels::frame_of(kernels::vec3_of(n));
  scale[l] = jets::gather_points(V, i, frame[l], ring, lane[l].points);
}

void LaneFits::run(PositionsRef V, int degree, bool robust, double floor, LocalSurface* out) {
  jets::JetBatch& b = batch;
  b.points_max = 0;
  for (int l = 0; l < width; ++l) {
    b.count[l] = l < queued && scale[l] > 0.0 ? static_cast<int>(lane[l].points.size()) : 0;
    b.points_max = std::max(b.points_max, b.count[l]);
  }
  // Every lane's points padded with (0, 0, 0) to points_max (JetBatch::points).
  const auto n = static_cast<std::size_t>(b.points_max);
  if (zeros.size() < n) zeros.resize(n, jets::Point{0.0, 0.0, 0.0});
  for (int l = 0; l < width; ++l) {
    if (b.count[l] == 0) {
      b.points[l] = zeros.data();
    } else {
      lane[l].points.resize(n, jets::Point{0.0, 0.0, 0.0});
      b.points[l] = lane[l].points.data();
    }
  }
  terms.resize(n * static_cast<std::size_t>(terms_stride(degree) * width));
  b.terms = terms.data();
  jets::top_degree_kernel(SimdIsa::best, degree)(b);
  const int m = coefficient_count(degree), moments = coefficient_count(2 * degree);
  for (int l = 0; l < queued; ++l) {
    out[l] = {};
    if (b.count[l] == 0 || !b.solved[l]) continue;
    // Lane l as the scalar fit of its points would leave it (the same bits).
    FitScratch& s = lane[l];
    s.points.resize(static_cast<std::size_t>(b.count[l]));
    jets::JetBatch& one = s.batch;
    one.points[0] = s.points.data();
    one.count[0] = one.points_max = b.count[l];
    one.solved[0] = true;
    for (int k = 0; k < moments; ++k) one.xy[k] = b.xy[k * width + l];
    for (int k = 0; k < m; ++k) one.z[k] = b.z[k * width + l], one.c[k] = b.c[k * width + l];
    out[l] = finish_fit(V, point[l], frame[l], scale[l], degree, robust, floor, s);
  }
  queued = 0;
}

}  // namespace focal::detail::smoothing
