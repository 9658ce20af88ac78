#include "curvature/robust_fit.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "core/result_rows.h"
#include "curvature/normal_rays_detail.h"
#include "curvature/two_slit_detail.h"

namespace focal::detail {
namespace {

struct Rays {
  VertexRays gathered;          ///< the rays (its weights: scratch of gather)
  std::vector<double> base;     ///< Gaussian (or 1) weight of each ray
  std::vector<double> weights;  ///< base x robust weight
  std::vector<double> misfit;   ///< |W x - g| at the current solution
  std::vector<double> sorted;
};

/// The rays of i's neighbours (not skipped, normal in i's hemisphere) in i's frame
/// (gather_rays), and their base weights.
void gather(const RobustFitInput& in, int i, const TangentFrame& frame, Rays& s) {
  const double inverse = in.gaussian_width > 0 ? 0.5 / (in.gaussian_width * in.gaussian_width) : 0;
  gather_rays(in.fit, i, frame, inverse, in.skip, s.gathered);
  if (s.gathered.weights.empty()) {
    s.base.assign(s.gathered.rays.size(), 1.0);
  } else {
    s.base.swap(s.gathered.weights);
  }
}

double median_of(std::vector<double>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// Weights: the base weight of rays within kRejectionScales robust scales of the fit, 0 beyond.
/// Returns how many rays are rejected (0 also when the scale is zero: the rays fit exactly).
int reject(Rays& s) {
  s.sorted = s.misfit;
  const double cut = kRejectionScales * 1.4826 * median_of(s.sorted);
  int rejected = 0;
  for (std::size_t k = 0; k < s.gathered.rays.size(); ++k) {
    const bool keep = !(s.misfit[k] > cut) || !(cut > 0.0);
    s.weights[k] = keep ? s.base[k] : 0.0;
    rejected += keep ? 0 : 1;
  }
  return rejected;
}

void measure_misfit(const kernels::SlitSolution<double>& w, Rays& s) {
  s.misfit.resize(s.gathered.rays.size());
  for (std::size_t k = 0; k < s.gathered.rays.size(); ++k) {
    const NormalRay& r = s.gathered.rays[k];
    s.misfit[k] = std::sqrt(kernels::slit_misfit(w, r.u, r.v, r.sigma, r.tau));
  }
}

}  // namespace

bool robust_fit_vertex(const RobustFitInput& in, int i, const ClassTolerances& tolerances,
                       CurvatureResult& r, Eigen::Index row) {
  thread_local Rays s;
  const VertexFitInput& f = in.fit;
  if (!f.normal_ok[static_cast<std::size_t>(i)]) {
    store_undefined(r, row);
    return false;
  }
  const TangentFrame frame = frame_of(f.unit_normals.row(i).transpose());
  gather(in, i, frame, s);
  s.weights = s.base;
  kernels::SlitSolution<double> w;
  if (!solve_well_conditioned(accumulate(s.gathered.rays, s.weights), w)) {
    store_undefined(r, row);
    return false;
  }
  bool rejected = false;
  for (int round = 0; round < kRejectionRounds && !s.gathered.rays.empty(); ++round) {
    measure_misfit(w, s);
    if (reject(s) == 0) break;
    kernels::SlitSolution<double> next;
    // Too few rays left (a vertex whose neighbours mostly disagree): keep the last fit.
    if (!solve_well_conditioned(accumulate(s.gathered.rays, s.weights), next)) break;
    w = next;
    rejected = true;
  }
  if (!rejected) s.weights = s.base;
  double weight_sum = 0.0;
  int used = 0;
  for (double x : s.weights) {
    weight_sum += x;
    used += x > 0.0 ? 1 : 0;
  }
  r.rays_used[row] = used;
  r.rays_excluded[row] = f.rings.size(i) - used;
  store_vertex(r, row, frame, principal_from_symmetric(w.a, w.b, w.c),
               std::sqrt(energy_of(s.gathered.rays, s.weights, w) / weight_sum), tolerances);
  return rejected;
}

void robust_fit_vertices(const RobustFitInput& in, const std::vector<int>& vertices,
                         const ClassTolerances& tolerances, int threads, bool only_rejecting,
                         CurvatureResult& r) {
  const auto n = static_cast<std::int64_t>(vertices.size());
  if (!only_rejecting) {
    parallel_for(n, threads, [&](std::int64_t k) {
      const int i = vertices[static_cast<std::size_t>(k)];
      robust_fit_vertex(in, i, tolerances, r, i);
    });
    return;
  }
  // Each vertex fitted into a one-row scratch of its block's, the row copied where rays were
  // rejected (a scratch of every row was a second result's memory, at the cloud default's peak).
  parallel_for_blocks(n, 256, threads, [&](std::int64_t begin, std::int64_t end) {
    CurvatureResult one = unwritten_result(1);
    for (std::int64_t k = begin; k < end; ++k) {
      const int i = vertices[static_cast<std::size_t>(k)];
      if (robust_fit_vertex(in, i, tolerances, one, 0)) copy_row(one, 0, r, i);
    }
  });
}

}  // namespace focal::detail
