#pragma once
// Host side of the per-vertex fit on a CUDA device (estimate_curvature_cuda): validation, the
// device's inputs built on the host, the outputs turned into a CurvatureResult, a CPU loop over
// the FOCAL_HD kernel (what the tests run everywhere) and ResidentVertexFit, the entry with the
// data kept on the device that bench/gpu times.
//
// Private: g++ compiles it for the tests, nvcc for src/cuda/vertex_fit.cu; no CUDA types here.

#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"
#include "focal/mesh/neighbourhood.h"
#include "kernels/vertex_fit.h"

namespace focal::cuda {

/// The checks of estimate_curvature (same conditions) plus what only the device path lacks.
/// \throw InvalidInput with a message naming estimate_curvature_cuda.
inline void validate_vertex_fit(PositionsRef V, FacesRef F, NormalsRef N,
                                const CurvatureOptions& o) {
  const std::string who = "estimate_curvature_cuda: ";
  if (o.method != Method::vertex) {
    throw InvalidInput(who +
                       "only Method::vertex runs here; use triangle_curvature_cuda or "
                       "estimate_curvature for Method::triangle");
  }
  if (o.solver != Solver::closed_form) {
    throw InvalidInput(who +
                       "only Solver::closed_form runs on the device; use estimate_curvature for "
                       "Solver::levenberg_marquardt");
  }
  if (o.rings < 1) throw InvalidInput(who + "rings must be >= 1, got " + std::to_string(o.rings));
  if (!(o.gaussian_width >= 0.0)) throw InvalidInput(who + "gaussian_width must be >= 0");
  if (!(o.tolerances.zero >= 0.0)) throw InvalidInput(who + "zero_tolerance must be >= 0");
  if (!(o.tolerances.umbilic >= 0.0)) throw InvalidInput(who + "umbilic_tolerance must be >= 0");
  if (N.rows() != V.rows()) {
    throw InvalidInput(who + std::to_string(N.rows()) + " normals for " + std::to_string(V.rows()) +
                       " vertices (normals are required; estimate them with vertex_normals)");
  }
  validate_mesh_arrays(V, F, N, "estimate_curvature_cuda");
}

/// Threshold of det / (trace/3)^3 below which a fit is `undefined`. The CPU (double) uses 1e-12.
/// In float the solution's relative error is at most cond x eps_f with cond <= 27 / threshold
/// (det = l1 l2 l3 <= l1^2 l3 and l1 <= trace), so 1e-4 bounds it by 3%: below that float
/// cannot resolve the fit and the vertex is flagged rather than given a number (docs/GPU.md).
template <class T>
constexpr double min_relative_determinant() {
  return sizeof(T) >= sizeof(double) ? 1e-12 : 1e-4;
}

/// hi + lo with lo the rounding error of hi: 2 x 24 bits carry a double to about 48 bits.
/// Out of line: inlined into a loop over a record's three coordinates, g++ 12 at -O3 vectorises
/// two of them and gives lo = 0 there (measured on every vertex of a torus), as if
/// double(float(x)) were x; called, it computes what it says.
template <class T>
[[gnu::noinline]] void split(double x, T& hi, T& lo) {
  hi = static_cast<T>(x);
  lo = static_cast<T>(x - static_cast<double>(hi));
}

/// Writes vertex i's unit normal (NaN where N's row is zero or not finite: its vertex is
/// `undefined`, as mesh/prepared_access.h's unit_rows) into its record as hi + lo pairs.
template <class T>
inline void set_record_normal(NormalsRef N, Eigen::Index i, VertexRecord<T>& r) {
  const double length = N.row(i).norm();
  const bool normal_ok = std::isfinite(length) && length > 0.0;
  for (int c = 0; c < 3; ++c)
    split(normal_ok ? N(i, c) / length : NAN, r.normal_hi[c], r.normal_lo[c]);
}

/// Everything the kernel reads, on the host; params holds the scalars (pointers unset).
template <class T>
struct PreparedVertexFit {
  std::vector<VertexRecord<T>> vertices;
  Neighbourhoods rings;
  VertexFitParams<T> params{};
};

/// Power of two near mean edge length x rings: positions divided by it stay exact and give
/// u, v = O(1). \throw InvalidInput when it is outside float's exponent range.
inline double length_unit(double mean_edge_length, int rings) {
  const double h = mean_edge_length * rings;
  if (!(h > 0.0) || !std::isfinite(h)) return 1.0;  // no edges: nothing to fit anyway
  const int e = std::ilogb(h);
  if (e < -100 || e > 100) {
    throw InvalidInput("estimate_curvature_cuda: mean edge length " + std::to_string(h / rings) +
                       " is outside the range float32 on the device handles (1e-30 .. 1e30); "
                       "rescale the mesh or use estimate_curvature");
  }
  return std::ldexp(1.0, e);
}

/// Validates and builds the device's inputs (see kernels/vertex_fit.h for the hi/lo pairs).
template <class T>
PreparedVertexFit<T> prepare_vertex_fit(PositionsRef V, FacesRef F, NormalsRef N,
                                        const CurvatureOptions& options) {
  validate_vertex_fit(V, F, N, options);
  PreparedVertexFit<T> p;
  const Eigen::Index n = V.rows();
  const double h = mean_edge_length(V, F);
  const double unit = length_unit(h, options.rings);
  p.vertices.resize(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    VertexRecord<T>& r = p.vertices[static_cast<std::size_t>(i)];
    for (int c = 0; c < 3; ++c) split(V(i, c) / unit, r.position_hi[c], r.position_lo[c]);
    set_record_normal(N, i, r);
  }
  const Neighbourhoods one_ring = vertex_adjacency(static_cast<int>(n), F);
  p.rings = options.rings == 1 ? one_ring : k_ring(one_ring, options.rings);
  // As curvature.cpp: Gaussian width = mean edge length x rings unless given; class_tolerances.
  const double width = options.gaussian_width > 0.0 ? options.gaussian_width : h * options.rings;
  VertexFitParams<T>& q = p.params;
  q.vertex_count = static_cast<int>(n);
  q.gaussian = options.weighting == RayWeighting::gaussian;
  q.inverse_two_width_squared = static_cast<T>(0.5 / (width * width) * unit * unit);
  q.curvature_unit = static_cast<T>(1.0 / unit);
  q.zero_tolerance = static_cast<T>(options.tolerances.zero / h);
  q.umbilic_tolerance = static_cast<T>(options.tolerances.umbilic);
  q.min_relative_determinant = static_cast<T>(min_relative_determinant<T>());
  return p;
}

/// Host copies of the kernel's outputs.
template <class T>
struct VertexFitFields {
  std::vector<T> k1, k2, H, K, d1, d2, residual;
  std::vector<std::uint8_t> point_class;
  std::vector<int> rays_used, rays_excluded;

  explicit VertexFitFields(std::size_t n)
      : k1(n),
        k2(n),
        H(n),
        K(n),
        d1(3 * n),
        d2(3 * n),
        residual(n),
        point_class(n),
        rays_used(n),
        rays_excluded(n) {}
  [[nodiscard]] VertexFitOutput<T> view() {
    return {k1.data(), k2.data(),       H.data(),           K.data(),         d1.data(),
            d2.data(), residual.data(), point_class.data(), rays_used.data(), rays_excluded.data()};
  }
};

/// The public result (doubles) of the kernel's outputs.
template <class T>
CurvatureResult to_result(const VertexFitFields<T>& f) {
  const auto n = static_cast<Eigen::Index>(f.k1.size());
  CurvatureResult r;
  const auto vector = [n](const std::vector<T>& v) {
    return Eigen::Map<const Eigen::Matrix<T, Eigen::Dynamic, 1>>(v.data(), n)
        .template cast<double>();
  };
  const auto rows = [n](const std::vector<T>& v) {
    return Eigen::Map<const Eigen::Matrix<T, Eigen::Dynamic, 3, Eigen::RowMajor>>(v.data(), n, 3)
        .template cast<double>();
  };
  r.k1 = vector(f.k1);
  r.k2 = vector(f.k2);
  r.H = vector(f.H);
  r.K = vector(f.K);
  r.residual = vector(f.residual);
  r.d1 = rows(f.d1);
  r.d2 = rows(f.d2);
  r.point_class = Eigen::Map<const VectorXu8>(f.point_class.data(), n);
  r.rays_used = Eigen::Map<const Eigen::VectorXi>(f.rays_used.data(), n);
  r.rays_excluded = Eigen::Map<const Eigen::VectorXi>(f.rays_excluded.data(), n);
  return r;
}

/// The device path's arithmetic run on the CPU, one vertex after another: what the tests
/// compare with estimate_curvature on machines without a GPU (T = float as on the device;
/// T = double checks the formula itself). \throw InvalidInput as estimate_curvature_cuda.
template <class T>
CurvatureResult fit_vertices_on_host(PositionsRef V, FacesRef F, NormalsRef N,
                                     const CurvatureOptions& options = {}) {
  PreparedVertexFit<T> p = prepare_vertex_fit<T>(V, F, N, options);
  VertexFitFields<T> fields(p.vertices.size());
  VertexFitParams<T> params = p.params;
  params.vertices = p.vertices.data();
  params.offsets = p.rings.offsets.data();
  params.indices = p.rings.indices.data();
  params.out = fields.view();
  for (int i = 0; i < params.vertex_count; ++i) fit_vertex(params, i);
  return to_result(fields);
}

/// The fit with its inputs resident on a device, for bench/gpu and estimate_curvature_cuda:
/// the constructor validates, builds the inputs and uploads them; run_kernel times the kernel
/// alone, run_with_transfers upload + kernel + download (CUDA events, milliseconds).
/// Defined in vertex_fit.cu (throws DeviceError in builds without CUDA: there is no definition).
class ResidentVertexFit {
 public:
  /// \throw DeviceError (no device, CUDA failure), InvalidInput as estimate_curvature_cuda.
  ResidentVertexFit(PositionsRef V, FacesRef F, NormalsRef N, const CurvatureOptions& options,
                    int device = 0);
  ~ResidentVertexFit();
  ResidentVertexFit(const ResidentVertexFit&) = delete;
  ResidentVertexFit& operator=(const ResidentVertexFit&) = delete;

  /// Replaces the normals (#V x 3, as the constructor's) and uploads the vertex records; the
  /// neighbourhoods and outputs stay on the device. \throw InvalidInput on a wrong row count.
  void set_normals(NormalsRef N);
  /// One launch over every vertex; returns the kernel's time in milliseconds.
  float run_kernel();
  /// Upload of the inputs, one launch, download of every output; milliseconds.
  float run_with_transfers();
  /// The outputs of the last run (downloaded now) as the public result.
  [[nodiscard]] CurvatureResult result() const;
  [[nodiscard]] int vertex_count() const;
  /// Bytes uploaded and downloaded by run_with_transfers (for bandwidth figures).
  [[nodiscard]] std::size_t transfer_bytes() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace focal::cuda
