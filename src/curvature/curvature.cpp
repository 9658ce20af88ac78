#include "focal/curvature/curvature.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "core/parallel.h"
#include "core/simd_lanes.h"
#include "curvature/normal_rays_detail.h"
#include "curvature/triangle_fit.h"
#include "curvature/two_slit_detail.h"
#include "curvature/vertex_fit.h"
#include "curvature/vertex_rows.h"
#include "focal/core/error.h"
#include "focal/curvature/normal_rays.h"
#include "focal/mesh/neighbourhood.h"
#include "kernels/local_shape.h"
#include "kernels/two_slit.h"
#include "kernels/vec3.h"
#include "mesh/prepared_access.h"

namespace focal {

void detail::validate_curvature_options(const CurvatureOptions& o) {
  if (o.rings < 1)
    throw InvalidInput("curvature: rings must be >= 1, got " + std::to_string(o.rings));
  if (!(o.gaussian_width >= 0.0)) throw InvalidInput("curvature: gaussian_width must be >= 0");
  if (!(o.tolerances.zero >= 0.0)) throw InvalidInput("curvature: zero_tolerance must be >= 0");
  if (!(o.tolerances.umbilic >= 0.0))
    throw InvalidInput("curvature: umbilic_tolerance must be >= 0");
}

namespace {

/// Everything one vertex's fit reads, shared by all vertices.
struct FitContext {
  const detail::VertexFitInput& in;
  const CurvatureOptions& options;
  double inverse_two_width_squared;  // Gaussian weights: exp(-d^2 * this)
  detail::ClassTolerances tolerances;
  /// When set, the k-th vertex fitted is vertices[k] (and its output goes to slot k), else k.
  const int* vertices = nullptr;
};

/// The Levenberg-Marquardt fit of vertex i (the closed form of every vertex runs in the lane
/// kernel below), on two_slit_detail.h's gather.
void fit_vertex(const FitContext& c, int i, detail::VertexRays& s, CurvatureResult& r) {
  r.rays_used[i] = r.rays_excluded[i] = 0;
  if (!c.in.normal_ok[static_cast<std::size_t>(i)]) return detail::store_undefined(r, i);
  const TangentFrame frame = detail::frame_of(c.in.unit_normals.row(i).transpose());
  const double inverse =
      c.options.weighting == RayWeighting::gaussian ? c.inverse_two_width_squared : 0.0;
  r.rays_excluded[i] = detail::gather_rays(c.in, i, frame, inverse, {}, s);
  r.rays_used[i] = static_cast<int>(s.rays.size());
  const SlitFit fit =
      fit_two_slits_levenberg_marquardt(s.rays, s.weights, c.options.levenberg_marquardt);
  if (!fit.valid) return detail::store_undefined(r, i);
  double weight_sum = static_cast<double>(s.rays.size());
  if (!s.weights.empty()) {
    weight_sum = 0.0;
    for (double w : s.weights) weight_sum += w;
  }
  detail::store_vertex(r, i, frame, {fit.k1, fit.k2, fit.d1, fit.d2},
                       std::sqrt(fit.energy / weight_sum), c.tolerances);
}

// ---- The closed-form fit, one vertex per lane.
//
// Vertices in groups of the lane width (simd_lanes.h): their frames, then their neighbours slot
// by slot (the k-th neighbour of every lane at once), the normal equations summed per lane in
// neighbour order, the 3x3 solve, the eigen-decomposition and the classification as selects.
// Lanes with fewer neighbours than the group's largest count are padded with rays of weight
// -0.0, which add exactly nothing (x + -0.0 == x, signed zeros included), so a lane's sums do not
// depend on its group: every instruction set, group width and thread count gives the same bits.
// Lanes with a degenerate fit (too few rays, singular system, invalid normal) get NaN and
// `undefined` by select, as store_undefined gives them in the scalar path.
//
// A tuned driver of kernels/two_slit.h (the plain one is two_slit_detail.h's). What it must
// match: each lane has the bits of the same formulas run on plain doubles one vertex at a time
// (kernels::frame_of, kernels::normal_ray and principal_axes with reciprocal quotients,
// add_ray in neighbour order, solve_slits, slit_misfit; tests/simd_kernels_test.cpp), and agrees
// with the scalar closed form (fit_two_slits_closed_form, whose ray slopes and direction are
// divided exactly) to rounding.

using detail::broadcast;
using detail::lane_count;
using detail::lanes_of;
using detail::MaskOf;
using detail::VertexFitInput;
using kernels::Quotient;
using kernels::Vec3;

/// One group of consecutive vertices: frame (x, y, n), position and neighbour lists per lane.
template <class L>
struct alignas(sizeof(L)) VertexGroup {
  static constexpr int kWidth = lane_count<L>;
  std::int64_t first = 0;
  int active = 0;  ///< lanes holding a vertex; the rest repeat the last one and are not stored
  int slots = 0;   ///< the largest neighbour count of the group
  L px, py, pz;
  kernels::Frame<L> frame;
  MaskOf<L> ok;  ///< -1 where the lane's vertex has a valid normal
  L count;       ///< neighbours per lane
  const int* ring[kWidth];
  int size[kWidth];
  int self[kWidth];  ///< the lane's vertex
};

/// One neighbour slot of a group: its rays (zero, weight -0.0, where a lane made none). The lane
/// structs are aligned explicitly: the alignment of a vector typedef is lost as a template
/// argument, and the AVX-512 code loads them with aligned moves.
template <class L>
struct alignas(sizeof(L)) RaySlot {
  L u, v, sigma, tau, weight;
};

/// Per-lane sums of the normal equations (kernels/two_slit.h) over the slots, of the weights,
/// and counts of rays made and of rays of positive weight (as -1 per ray).
template <class L>
struct alignas(sizeof(L)) SlotSums {
  kernels::SlitSums<L> equations;
  L weight{};
  MaskOf<L> used{}, positive{};
};

/// matrix(rows[l], col) in lane l.
template <class L, class Matrix>
[[gnu::always_inline]] inline L column(const Matrix& matrix, const int* rows, int col) {
  return lanes_of<L>([&](int l) { return matrix(rows[l], col); });
}

/// -1 in lane l where flags[rows[l]] is set.
template <class L>
[[gnu::always_inline]] inline MaskOf<L> flags(const std::vector<char>& flags, const int* rows) {
  return lanes_of<MaskOf<L>>([&](int l) {
    return flags[static_cast<std::size_t>(rows[l])] ? std::int64_t{-1} : std::int64_t{0};
  });
}

template <class L>
[[gnu::always_inline]] inline void load_group(const VertexFitInput& in, const int* vertices,
                                              std::int64_t first, int active, VertexGroup<L>& g) {
  g.first = first;
  g.active = active;
  g.slots = 0;
  for (int l = 0; l < g.kWidth; ++l) {
    const std::int64_t k = first + std::min(l, active - 1);
    const int i = vertices ? vertices[k] : static_cast<int>(k);
    g.self[l] = i;
    g.ring[l] = in.rings.begin(i);
    g.size[l] = l < active ? in.rings.size(i) : 0;
    g.slots = std::max(g.slots, g.size[l]);
  }
  const PositionsRef& V = in.V;
  const RowMatrixX3d& N = in.unit_normals;
  g.px = column<L>(V, g.self, 0), g.py = column<L>(V, g.self, 1), g.pz = column<L>(V, g.self, 2);
  g.count = lanes_of<L>([&](int l) { return static_cast<double>(g.size[l]); });
  g.ok = flags<L>(in.normal_ok, g.self) &
         (lanes_of<L>([](int l) { return static_cast<double>(l); }) < active);
  // An invalid normal is replaced by +z so that its lane computes finite values; the lane is
  // stored as undefined.
  const L zero{};
  g.frame = kernels::frame_of(Vec3<L>{g.ok ? column<L>(N, g.self, 0) : zero,
                                      g.ok ? column<L>(N, g.self, 1) : zero,
                                      g.ok ? column<L>(N, g.self, 2) : broadcast<L>(1.0)});
}

/// The rays of slot k of every lane (kernels::normal_ray), added to the sums. Lanes with fewer
/// than k + 1 neighbours read their own vertex and do not count it.
template <class L>
[[gnu::always_inline]] inline void make_slot(const FitContext& c, const VertexGroup<L>& g, int k,
                                             RaySlot<L>& out, SlotSums<L>& sums) {
  const VertexFitInput& in = c.in;
  int j[g.kWidth];
  for (int l = 0; l < g.kWidth; ++l) j[l] = k < g.size[l] ? g.ring[l][k] : g.self[l];
  const PositionsRef& V = in.V;
  const RowMatrixX3d& N = in.unit_normals;
  const Vec3<L> d{column<L>(V, j, 0) - g.px, column<L>(V, j, 1) - g.py, column<L>(V, j, 2) - g.pz};
  const Vec3<L> m{column<L>(N, j, 0), column<L>(N, j, 1), column<L>(N, j, 2)};
  L weight = broadcast<L>(1.0);
  if (c.options.weighting == RayWeighting::gaussian) {
    const L d2 = d.x * d.x + d.y * d.y + d.z * d.z;
    weight = lanes_of<L>([&](int l) { return std::exp(-d2[l] * c.inverse_two_width_squared); });
  }
  // One reciprocal, not two divisions: the divider is the narrowest port here.
  kernels::NormalRay<L> ray;
  const auto made = g.ok & (static_cast<double>(k) < g.count) & flags<L>(in.normal_ok, j) &
                    kernels::normal_ray<Quotient::reciprocal>(g.frame, d, m, m, ray);
  const L zero{};
  out.u = made ? ray.u : zero;
  out.v = made ? ray.v : zero;
  out.sigma = made ? ray.sigma : zero;
  out.tau = made ? ray.tau : zero;
  out.weight = made ? weight : broadcast<L>(-0.0);
  const L w = out.weight;
  kernels::add_ray(sums.equations, w, out.u, out.v, out.sigma, out.tau);
  sums.weight += w;
  sums.used += made;
  sums.positive += made & (w > 0.0);
}

/// A group's results, NaN and `undefined` where its fit is not valid.
template <class L>
struct alignas(sizeof(L)) GroupResult {
  L k1, k2, H, K, residual, d1x, d1y, d1z, d2x, d2y, d2z;
  MaskOf<L> point_class, used, excluded;
};

template <class L>
[[gnu::always_inline]] inline void store_group(const VertexGroup<L>& g, const GroupResult<L>& x,
                                               CurvatureResult& r) {
  const std::int64_t i = g.first;
  if (g.active == g.kWidth) {
    using detail::store_lanes;
    store_lanes(r.k1.data() + i, x.k1), store_lanes(r.k2.data() + i, x.k2);
    store_lanes(r.H.data() + i, x.H), store_lanes(r.K.data() + i, x.K);
    store_lanes(r.residual.data() + i, x.residual);
  } else {
    for (int l = 0; l < g.active; ++l) {
      r.k1[i + l] = x.k1[l], r.k2[i + l] = x.k2[l], r.H[i + l] = x.H[l], r.K[i + l] = x.K[l];
      r.residual[i + l] = x.residual[l];
    }
  }
  double* d1 = r.d1.data() + 3 * i;
  double* d2 = r.d2.data() + 3 * i;
  for (int l = 0; l < g.active; ++l) {
    d1[3 * l] = x.d1x[l], d1[3 * l + 1] = x.d1y[l], d1[3 * l + 2] = x.d1z[l];
    d2[3 * l] = x.d2x[l], d2[3 * l + 1] = x.d2y[l], d2[3 * l + 2] = x.d2z[l];
    r.point_class[i + l] = static_cast<std::uint8_t>(x.point_class[l]);
    r.rays_used[i + l] = static_cast<int>(x.used[l]);
    r.rays_excluded[i + l] = static_cast<int>(x.excluded[l]);
  }
}

/// The output of the roughness-only fit (detail::fit_roughness): one double per vertex.
struct Roughness {
  double* data;
};

/// Roughness of a group: the residual where the fit is valid and made a ray of every neighbour.
template <class L>
[[gnu::always_inline]] inline void store_roughness(const VertexGroup<L>& g, L roughness,
                                                   Roughness& out) {
  if (g.active == g.kWidth) return detail::store_lanes(out.data + g.first, roughness);
  for (int l = 0; l < g.active; ++l) out.data[g.first + l] = roughness[l];
}

/// The closed-form fit of one group (kernels/two_slit.h), one vertex per lane, into every field
/// of `r` (a CurvatureResult), or only its roughness (a Roughness: no principal axes, classes or
/// directions computed, no other array written).
template <class L, class Out>
[[gnu::always_inline]] inline void fit_group(const FitContext& c, std::int64_t first, int active,
                                             std::vector<RaySlot<L>>& slots, Out& r) {
  VertexGroup<L> g;
  load_group(c.in, c.vertices, first, active, g);
  if (slots.size() < static_cast<std::size_t>(g.slots)) slots.resize(g.slots);
  SlotSums<L> sums;
  for (int k = 0; k < g.slots; ++k) make_slot(c, g, k, slots[k], sums);
  const kernels::SlitSolution<L> w =
      kernels::solve_slits(sums.equations, detail::kMinRelativeDeterminant);
  const auto used = -sums.used;
  const auto valid = g.ok & (-sums.positive >= 2) & w.valid;
  L energy{};
  for (int k = 0; k < g.slots; ++k) {
    const RaySlot<L>& ray = slots[k];
    energy += ray.weight * kernels::slit_misfit(w, ray.u, ray.v, ray.sigma, ray.tau);
  }
  const L weight_sum = c.options.weighting == RayWeighting::gaussian
                           ? sums.weight
                           : __builtin_convertvector(used, L);
  const L nan = broadcast<L>(std::numeric_limits<double>::quiet_NaN());
  const L residual = detail::lane_sqrt(energy / weight_sum);
  const MaskOf<L> none{};
  const auto excluded = g.ok ? __builtin_convertvector(g.count, MaskOf<L>) - used : none;
  if constexpr (std::is_same_v<Out, Roughness>) {
    return store_roughness(g, valid & (excluded == 0) ? residual : nan, r);
  } else {
    // Both divisions by one reciprocal, for the divider's sake as in make_slot.
    const kernels::Principal<L> p =
        kernels::principal_axes<Quotient::reciprocal, Quotient::reciprocal>(w.a, w.b, w.c);
    const auto or_nan = [&](L x) FOCAL_LANE_LAMBDA { return valid ? x : nan; };
    GroupResult<L> x;
    x.k1 = or_nan(p.k1), x.k2 = or_nan(p.k2);
    x.H = or_nan(0.5 * (p.k1 + p.k2)), x.K = or_nan(p.k1 * p.k2);
    x.residual = or_nan(residual);
    // d2 = d1 turned by +90 degrees.
    const Vec3<L> d1 = g.frame.from_plane(p.d1x, p.d1y), d2 = g.frame.from_plane(-p.d1y, p.d1x);
    x.d1x = or_nan(d1.x), x.d1y = or_nan(d1.y), x.d1z = or_nan(d1.z);
    x.d2x = or_nan(d2.x), x.d2y = or_nan(d2.y), x.d2z = or_nan(d2.z);
    x.point_class = valid ? kernels::classify(x.k1, x.k2, c.tolerances.zero, c.tolerances.umbilic)
                          : kernels::class_code<L>(PointClass::undefined);
    x.used = g.ok ? used : none;
    x.excluded = excluded;
    store_group(g, x, r);
  }
}

/// The closed-form fit of vertices [begin, end), one group after the other.
template <class L, class Out>
[[gnu::always_inline]] inline void fit_block_lanes(const FitContext& c, std::int64_t begin,
                                                   std::int64_t end, Out& r) {
  constexpr int kWidth = lane_count<L>;
  std::vector<RaySlot<L>> slots(8);
  for (std::int64_t first = begin; first < end; first += kWidth) {
    fit_group<L>(c, first, static_cast<int>(std::min<std::int64_t>(kWidth, end - first)), slots, r);
  }
}

template <class Out>
FOCAL_TARGET_AVX512 void fit_block_avx512(const FitContext& c, std::int64_t begin, std::int64_t end,
                                          Out& r) {
  fit_block_lanes<detail::Lanes8>(c, begin, end, r);
}
template <class Out>
FOCAL_TARGET_AVX2 void fit_block_avx2(const FitContext& c, std::int64_t begin, std::int64_t end,
                                      Out& r) {
  fit_block_lanes<detail::Lanes4>(c, begin, end, r);
}
template <class Out>
void fit_block_baseline(const FitContext& c, std::int64_t begin, std::int64_t end, Out& r) {
  fit_block_lanes<detail::Lanes2>(c, begin, end, r);
}

template <class Out>
using FitBlock = void (*)(const FitContext&, std::int64_t, std::int64_t, Out&);

template <class Out>
FitBlock<Out> fit_block_for(detail::SimdIsa isa) {
  return detail::kernel_for<FitBlock<Out>>(isa, fit_block_avx512<Out>, fit_block_avx2<Out>,
                                           fit_block_baseline<Out>);
}

/// The fit's context: Gaussian width and class tolerances from the options.
FitContext fit_context(const detail::VertexFitInput& in, const CurvatureOptions& options) {
  const double h = in.mean_edge_length;
  const double width = options.gaussian_width > 0.0 ? options.gaussian_width : h * options.rings;
  return {in, options, 0.5 / (width * width), detail::class_tolerances(options, h), nullptr};
}

}  // namespace

CurvatureResult detail::vertex_curvature_from_rays(const PreparedMesh& mesh,
                                                   const Neighbourhoods& one_ring,
                                                   const CurvatureOptions& options) {
  CurvatureOptions o = options;
  const UnitNormals& unit = unit_normals(mesh);
  const VertexFitInput in{mesh.V(), unit.N, unit.ok, one_ring, mesh.mean_edge_length()};
  if (o.rings == 1) return fit_vertices(in, o);
  const Neighbourhoods rings = k_ring(one_ring, o.rings);
  return fit_vertices({in.V, unit.N, unit.ok, rings, in.mean_edge_length}, o);
}

PointClass classify(double k1, double k2, double zero_tolerance, double umbilic_tolerance) {
  return static_cast<PointClass>(kernels::classify(k1, k2, zero_tolerance, umbilic_tolerance));
}

CurvatureResult estimate_curvature(const PreparedMesh& mesh, const CurvatureOptions& options) {
  detail::validate_curvature_options(options);
  if (!mesh.has_normals()) {
    throw InvalidInput(
        "curvature: the mesh has no normals (they are required; estimate them with "
        "vertex_normals)");
  }
  if (options.method == Method::triangle) {
    return detail::vertex_curvature_from_triangles(mesh, options);
  }
  return detail::vertex_curvature_from_rays(mesh, *detail::one_ring(mesh), options);
}

CurvatureResult estimate_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                   const CurvatureOptions& options) {
  detail::validate_curvature_options(options);
  return estimate_curvature(detail::PreparedAccess::make(V, F, N, {}, "curvature"), options);
}

namespace detail {

CurvatureResult fit_vertices(const VertexFitInput& in, const CurvatureOptions& options,
                             SimdIsa isa) {
  const FitContext context = fit_context(in, options);
  CurvatureResult result = unwritten_result(in.V.rows());
  const FitBlock<CurvatureResult> fit_block = fit_block_for<CurvatureResult>(isa);
  // Blocks of vertices share one scratch; 256 vertices amortise its allocation and still give
  // each thread many blocks (static schedule, so the same split for any run). Blocks are whole
  // groups of any lane width, so a group never straddles two threads' output.
  parallel_for_blocks(in.V.rows(), 256, 0, [&](std::int64_t begin, std::int64_t end) {
    if (options.solver == Solver::closed_form) return fit_block(context, begin, end, result);
    detail::VertexRays scratch;
    for (auto i = begin; i < end; ++i) fit_vertex(context, static_cast<int>(i), scratch, result);
  });
  return result;
}

Eigen::VectorXd fit_roughness(const VertexFitInput& in, const CurvatureOptions& options,
                              SimdIsa isa) {
  return fit_roughness_at(in, options, nullptr, in.V.rows(), isa);
}

Eigen::VectorXd fit_roughness_at(const VertexFitInput& in, const CurvatureOptions& options,
                                 const int* vertices, Eigen::Index count, SimdIsa isa) {
  if (options.solver != Solver::closed_form) {
    throw InvalidInput("fit_roughness: only the closed-form solver");
  }
  FitContext context = fit_context(in, options);
  context.vertices = vertices;
  Eigen::VectorXd roughness(count);
  Roughness out{roughness.data()};
  const FitBlock<Roughness> fit_block = fit_block_for<Roughness>(isa);
  parallel_for_blocks(count, 256, 0, [&](std::int64_t begin, std::int64_t end) {
    fit_block(context, begin, end, out);
  });
  return roughness;
}

}  // namespace detail
}  // namespace focal
