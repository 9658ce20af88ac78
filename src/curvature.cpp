#include "focal/curvature.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "curvature_detail.h"
#include "focal/error.h"
#include "focal/neighbourhood.h"
#include "focal/normal_rays.h"
#include "normal_rays_detail.h"
#include "parallel.h"
#include "two_slit_detail.h"

namespace focal {

// Implemented in triangle_curvature.cpp: Method::triangle.
CurvatureResult vertex_curvature_from_triangles(PositionsRef V, FacesRef F, NormalsRef N,
                                                const CurvatureOptions& options);

namespace {

void validate_options(const CurvatureOptions& o) {
  if (o.rings < 1)
    throw InvalidInput("curvature: rings must be >= 1, got " + std::to_string(o.rings));
  if (!(o.gaussian_width >= 0.0)) throw InvalidInput("curvature: gaussian_width must be >= 0");
  if (!(o.zero_tolerance >= 0.0)) throw InvalidInput("curvature: zero_tolerance must be >= 0");
  if (!(o.umbilic_tolerance >= 0.0))
    throw InvalidInput("curvature: umbilic_tolerance must be >= 0");
  if (o.threads < 0) throw InvalidInput("curvature: threads must be >= 0");
}

/// Everything one vertex's fit reads, shared by all vertices.
struct FitContext {
  const detail::VertexFitInput& in;
  const CurvatureOptions& options;
  double inverse_two_width_squared;  // Gaussian weights: exp(-d^2 * this)
  detail::ClassTolerances tolerances;
};

/// One vertex's rays and weights. Owned by a block of vertices, so that the loop over vertices
/// never touches the heap once the vectors have grown to the largest ring.
struct RayScratch {
  std::vector<NormalRay> rays;
  std::vector<double> weights;  // empty for uniform weights
};

SlitFit run_solver(const CurvatureOptions& o, std::span<const NormalRay> rays,
                   std::span<const double> weights) {
  return o.solver == Solver::closed_form
             ? detail::closed_form_fit(rays, weights)
             : fit_two_slits_levenberg_marquardt(rays, weights, o.levenberg_marquardt);
}

/// The rays of vertex i's neighbours in its tangent frame (paper 4.1); returns how many
/// neighbours had none (normal outside the hemisphere, or invalid).
int gather_rays(const FitContext& c, int i, const TangentFrame& frame, RayScratch& s) {
  const detail::VertexFitInput& in = c.in;
  const Eigen::Vector3d p = in.V.row(i).transpose();
  int excluded = 0;
  for (const int* j = in.rings.begin(i); j != in.rings.end(i); ++j) {
    const Eigen::Vector3d q = in.V.row(*j).transpose();
    // The ray is made in its slot: copying a just-written NormalRay into the vector stalled on
    // store forwarding (a fifth of the fit's time).
    NormalRay& ray = s.rays.emplace_back();
    if (!in.normal_ok[static_cast<std::size_t>(*j)] ||
        !detail::ray_of(frame, p, q, in.unit_normals.row(*j).transpose(), ray)) {
      s.rays.pop_back();
      ++excluded;
      continue;
    }
    if (c.options.weighting == RayWeighting::gaussian) {
      s.weights.push_back(std::exp(-(q - p).squaredNorm() * c.inverse_two_width_squared));
    }
  }
  return excluded;
}

void fit_vertex(const FitContext& c, int i, RayScratch& s, CurvatureResult& r) {
  s.rays.clear();
  s.weights.clear();
  r.rays_used[i] = r.rays_excluded[i] = 0;
  if (!c.in.normal_ok[static_cast<std::size_t>(i)]) return detail::store_undefined(r, i);
  const TangentFrame frame = detail::frame_of(c.in.unit_normals.row(i).transpose());
  r.rays_excluded[i] = gather_rays(c, i, frame, s);
  r.rays_used[i] = static_cast<int>(s.rays.size());
  const SlitFit fit = run_solver(c.options, s.rays, s.weights);
  if (!fit.valid) return detail::store_undefined(r, i);
  double weight_sum = static_cast<double>(s.rays.size());
  if (!s.weights.empty()) {
    weight_sum = 0.0;
    for (double w : s.weights) weight_sum += w;
  }
  detail::store_vertex(r, i, frame, {fit.k1, fit.k2, fit.d1, fit.d2},
                       std::sqrt(fit.energy / weight_sum), c.tolerances);
}

// ---- The closed-form fit over lanes of neighbours.
//
// The rays of one vertex are made and summed four neighbours at a time, structure of arrays in
// GCC vector types: two SSE2 registers per lane group on baseline x86-64, one AVX2 register in
// the clone below. Each lane keeps its own partial sums, added in one fixed order at the end, so
// every build and every thread count gives the same bits. No FMA is enabled in either clone, so
// no multiply-add is contracted differently between them.

using detail::frame_of;
using detail::NormalEquations;
using detail::principal_from_symmetric;
using detail::solve_well_conditioned;
using detail::store_undefined;
using detail::store_vertex;
using detail::VertexFitInput;

constexpr int kLanes = 4;
// Aligned explicitly: without AVX, GCC gives 32-byte vectors only 16-byte alignment, while the
// AVX2 clone loads them with aligned 32-byte moves.
using Lanes = double __attribute__((vector_size(kLanes * sizeof(double)), aligned(32)));
using LaneMask = std::int64_t __attribute__((vector_size(kLanes * sizeof(double)), aligned(32)));

/// Four neighbours as read from the mesh: offset q = position - vertex, unit normal, validity.
struct alignas(32) NeighbourLanes {
  Lanes qx, qy, qz, nx, ny, nz;
  Lanes weight;  // 1 (uniform) or the Gaussian weight; 0 for padding and invalid normals
  LaneMask ok;   // -1 where the neighbour's normal is valid
};

/// Four rays in the tangent frame, zero (and weight 0) where a neighbour gave no ray.
struct alignas(32) RayLanes {
  Lanes u, v, sigma, tau, weight;
};

/// Lane storage of one block of vertices, grown to its largest neighbourhood and then reused.
struct LaneScratch {
  std::vector<NeighbourLanes> in;
  std::vector<RayLanes> rays;
};

[[gnu::always_inline]] inline double lane_sum(const Lanes& x) {
  return (x[0] + x[1]) + (x[2] + x[3]);
}

[[gnu::always_inline]] inline std::int64_t lane_count(const LaneMask& m) {
  return -((m[0] + m[1]) + (m[2] + m[3]));
}

/// Fills the lanes with vertex i's neighbours, padding the last group with a neighbour at the
/// vertex whose normal is the vertex's own (a finite ray of zeros) marked not ok.
[[gnu::always_inline]] inline std::size_t gather_lanes(const FitContext& c, int i,
                                                       const Eigen::Vector3d& n, LaneScratch& s) {
  const VertexFitInput& in = c.in;
  const int count = in.rings.size(i);
  const auto groups = static_cast<std::size_t>((count + kLanes - 1) / kLanes);
  if (s.in.size() < groups) s.in.resize(groups), s.rays.resize(groups);
  const double p[3] = {in.V(i, 0), in.V(i, 1), in.V(i, 2)};
  const int* ring = in.rings.begin(i);
  const bool gaussian = c.options.weighting == RayWeighting::gaussian;
  for (int k = 0; k < static_cast<int>(groups) * kLanes; ++k) {
    NeighbourLanes& g = s.in[static_cast<std::size_t>(k / kLanes)];
    const int lane = k % kLanes;
    if (k >= count) {
      g.qx[lane] = g.qy[lane] = g.qz[lane] = 0.0;
      g.nx[lane] = n.x(), g.ny[lane] = n.y(), g.nz[lane] = n.z();
      g.weight[lane] = 0.0;
      g.ok[lane] = 0;
      continue;
    }
    const int j = ring[k];
    const double qx = in.V(j, 0) - p[0], qy = in.V(j, 1) - p[1], qz = in.V(j, 2) - p[2];
    g.qx[lane] = qx, g.qy[lane] = qy, g.qz[lane] = qz;
    g.nx[lane] = in.unit_normals(j, 0), g.ny[lane] = in.unit_normals(j, 1);
    g.nz[lane] = in.unit_normals(j, 2);
    g.weight[lane] =
        gaussian ? std::exp(-(qx * qx + qy * qy + qz * qz) * c.inverse_two_width_squared) : 1.0;
    g.ok[lane] = in.normal_ok[static_cast<std::size_t>(j)] ? -1 : 0;
  }
  return groups;
}

/// The paper's ray of each lane (detail::ray_of, same formulas), and its terms of the normal
/// equations added to the lane sums: lhs (uu, uv, vv) and rhs (us, vs + ut, vt) weighted.
struct alignas(32) LaneSums {
  Lanes uu{}, uv{}, vv{}, r0{}, r1{}, r2{};
  LaneMask used{}, positive{};  // -1 per ray made; per ray made with weight > 0
};

[[gnu::always_inline]] inline void make_rays(const TangentFrame& f, const NeighbourLanes& g,
                                             RayLanes& out, LaneSums& sums) {
  const Lanes mz = f.n.x() * g.nx + f.n.y() * g.ny + f.n.z() * g.nz;
  const Lanes qz = f.n.x() * g.qx + f.n.y() * g.qy + f.n.z() * g.qz;
  const Lanes sigma = (f.x.x() * g.nx + f.x.y() * g.ny + f.x.z() * g.nz) / mz;
  const Lanes tau = (f.y.x() * g.nx + f.y.y() * g.ny + f.y.z() * g.nz) / mz;
  const Lanes u = (f.x.x() * g.qx + f.x.y() * g.qy + f.x.z() * g.qz) - qz * sigma;
  const Lanes v = (f.y.x() * g.qx + f.y.y() * g.qy + f.y.z() * g.qz) - qz * tau;
  const Lanes total = sigma + tau + u + v;
  // mz > 0 also rejects NaN; total - total is 0 exactly when the ray is finite.
  const LaneMask made = g.ok & (mz > 0.0) & (total - total == 0.0);
  const Lanes zero{};
  out.u = made ? u : zero;
  out.v = made ? v : zero;
  out.sigma = made ? sigma : zero;
  out.tau = made ? tau : zero;
  out.weight = made ? g.weight : zero;
  const Lanes w = out.weight;
  sums.uu += w * out.u * out.u;
  sums.uv += w * out.u * out.v;
  sums.vv += w * out.v * out.v;
  sums.r0 += w * (out.u * out.sigma);
  sums.r1 += w * (out.v * out.sigma + out.u * out.tau);
  sums.r2 += w * (out.v * out.tau);
  sums.used += made;
  sums.positive += made & (w > 0.0);
}

/// sum_i w_i |W x_i - g_i|^2 over the lanes (energy_of_matrix's formula).
[[gnu::always_inline]] inline double lane_energy(const LaneScratch& s, std::size_t groups, double a,
                                                 double b, double c) {
  Lanes e{};
  for (std::size_t k = 0; k < groups; ++k) {
    const RayLanes& r = s.rays[k];
    const Lanes ru = a * r.u + b * r.v - r.sigma;
    const Lanes rv = b * r.u + c * r.v - r.tau;
    e += r.weight * (ru * ru + rv * rv);
  }
  return lane_sum(e);
}

[[gnu::always_inline]] inline void fit_vertex_closed_form(const FitContext& c, int i,
                                                          LaneScratch& s, CurvatureResult& r) {
  r.rays_used[i] = r.rays_excluded[i] = 0;
  if (!c.in.normal_ok[static_cast<std::size_t>(i)]) return store_undefined(r, i);
  const TangentFrame frame = frame_of(c.in.unit_normals.row(i).transpose());
  const std::size_t groups = gather_lanes(c, i, frame.n, s);
  LaneSums sums;
  for (std::size_t k = 0; k < groups; ++k) make_rays(frame, s.in[k], s.rays[k], sums);
  const auto used = static_cast<int>(lane_count(sums.used));
  r.rays_used[i] = used;
  r.rays_excluded[i] = c.in.rings.size(i) - used;
  NormalEquations eq;
  eq.lhs << lane_sum(sums.uu), lane_sum(sums.uv), 0.0,                //
      0.0, lane_sum(sums.uu) + lane_sum(sums.vv), lane_sum(sums.uv),  //
      0.0, 0.0, lane_sum(sums.vv);
  eq.lhs(1, 0) = eq.lhs(0, 1);
  eq.lhs(2, 1) = eq.lhs(1, 2);
  eq.rhs << lane_sum(sums.r0), lane_sum(sums.r1), lane_sum(sums.r2);
  eq.rays = static_cast<int>(lane_count(sums.positive));
  Eigen::Vector3d w;
  if (!solve_well_conditioned(eq, w)) return store_undefined(r, i);
  double weight_sum = used;
  if (c.options.weighting == RayWeighting::gaussian) {
    Lanes total{};
    for (std::size_t k = 0; k < groups; ++k) total += s.rays[k].weight;
    weight_sum = lane_sum(total);
  }
  const double energy = lane_energy(s, groups, w[0], w[1], w[2]);
  store_vertex(r, i, frame, principal_from_symmetric(w[0], w[1], w[2]),
               std::sqrt(energy / weight_sum), c.tolerances);
}

/// The closed-form fit of vertices [begin, end), compiled twice: for AVX2 and for baseline
/// x86-64, chosen once at load time by the CPU (same results, see above).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default")))
#endif
void fit_block_closed_form(const FitContext& c, std::int64_t begin, std::int64_t end,
                           LaneScratch& s, CurvatureResult& r) {
  for (auto i = begin; i < end; ++i) fit_vertex_closed_form(c, static_cast<int>(i), s, r);
}

CurvatureResult vertex_curvature_from_rays(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options) {
  std::vector<char> normal_ok;
  const RowMatrixX3d unit = detail::unit_rows(N, normal_ok, options.threads);
  const Neighbourhoods one_ring = vertex_adjacency(static_cast<int>(V.rows()), F);
  const Neighbourhoods rings = options.rings == 1 ? one_ring : k_ring(one_ring, options.rings);
  return detail::fit_vertices({V, unit, normal_ok, rings, mean_edge_length(V, F)}, options);
}

}  // namespace

std::string_view class_name(PointClass c) {
  switch (c) {
    case PointClass::elliptic:
      return "elliptic";
    case PointClass::hyperbolic:
      return "hyperbolic";
    case PointClass::parabolic:
      return "parabolic";
    case PointClass::umbilic:
      return "umbilic";
    case PointClass::flat:
      return "flat";
    case PointClass::undefined:
      return "undefined";
  }
  return "undefined";
}

PointClass classify(double k1, double k2, double zero_tolerance, double umbilic_tolerance) {
  if (!std::isfinite(k1) || !std::isfinite(k2)) return PointClass::undefined;
  const bool zero1 = std::abs(k1) <= zero_tolerance, zero2 = std::abs(k2) <= zero_tolerance;
  if (zero1 && zero2) return PointClass::flat;
  if (zero1 || zero2) return PointClass::parabolic;
  if (k1 - k2 <= umbilic_tolerance * std::max(std::abs(k1), std::abs(k2)))
    return PointClass::umbilic;
  return k1 * k2 > 0.0 ? PointClass::elliptic : PointClass::hyperbolic;
}

CurvatureResult estimate_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                   const CurvatureOptions& options) {
  validate_options(options);
  if (N.rows() != V.rows()) {
    throw InvalidInput("curvature: " + std::to_string(N.rows()) + " normals for " +
                       std::to_string(V.rows()) +
                       " vertices (normals are required; estimate "
                       "them with vertex_normals)");
  }
  validate_mesh_arrays(V, F, N, "curvature");
  if (options.method == Method::triangle) return vertex_curvature_from_triangles(V, F, N, options);
  return vertex_curvature_from_rays(V, F, N, options);
}

namespace detail {

CurvatureResult fit_vertices(const VertexFitInput& in, const CurvatureOptions& options) {
  const double h = in.mean_edge_length;
  const double width = options.gaussian_width > 0.0 ? options.gaussian_width : h * options.rings;
  const FitContext context{in, options, 0.5 / (width * width), class_tolerances(options, h)};
  CurvatureResult result = unwritten_result(in.V.rows());
  // Blocks of vertices share one scratch; 256 vertices amortise its allocation and still give
  // each thread many blocks (static schedule, so the same split for any run).
  parallel_for_blocks(in.V.rows(), 256, options.threads, [&](std::int64_t begin, std::int64_t end) {
    if (options.solver == Solver::closed_form) {
      LaneScratch scratch;
      fit_block_closed_form(context, begin, end, scratch, result);
      return;
    }
    RayScratch scratch;
    for (auto i = begin; i < end; ++i) fit_vertex(context, static_cast<int>(i), scratch, result);
  });
  return result;
}

}  // namespace detail
}  // namespace focal
