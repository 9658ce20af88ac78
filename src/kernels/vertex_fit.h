#pragma once
// The per-vertex closed-form two-slit fit (paper section 5; docs/notes/estimator-log.md) as plain-data
// math that nvcc compiles into the CUDA kernel and g++ into the CPU test that checks it against
// estimate_curvature. No Eigen, no allocation: one thread runs fit_vertex for one vertex.
//
// The frame of Duff et al., the rays of paper eq. 3, the eigen-decomposition and the
// classification are kernels/local_shape.h's, the normal equations in W = [a b; b c], their
// solve and the misfit kernels/two_slit.h's: those of every estimator. All in an arithmetic type
// T (float on the device, double to check the formula). Three changes keep
// float32 accurate to a few units of its rounding relative to the curvature, whatever the mesh
// size, units or placement (docs/GPU.md):
//  - Positions and normals arrive as float pairs hi + lo (lo = the rounding error of hi). A
//    neighbour's offset (q_hi - p_hi) + (q_lo - p_lo) is then exact to float rounding relative to
//    the edge length, not to the coordinates' magnitude (1e-4 edge lengths on a 1M-vertex mesh).
//  - The slopes use the normal's change D = M - N (from the pairs): x.M = x.D because x is
//    orthogonal to N, and x.D has float rounding relative to |D| ~ |k| h, where x.M computed from
//    rounded M would carry an absolute 6e-8 (relative 6e-8 / (|k| h)).
//  - Positions are scaled by a power of two near 1 / (mean edge length x rings), exactly, so that
//    u, v are O(1) in every unit system: the normal equations' sums are then O(rays) and their
//    determinant O(rays^3), far inside float's range for any neighbourhood.

#include <cmath>
#include <cstdint>

#include "focal/core/point_class.h"
#include "kernels/host_device.h"
#include "kernels/local_shape.h"
#include "kernels/two_slit.h"
#include "kernels/vec3.h"

namespace focal::cuda {

/// One vertex's data, gathered by every neighbour's thread: 48 contiguous bytes in float.
/// position = position_hi + position_lo, likewise the unit normal; normal_hi is NaN where the
/// input normal was zero or not finite (the vertex is undefined and no neighbour uses its ray).
template <class T>
struct alignas(16) VertexRecord {
  T position_hi[3];
  T position_lo[3];
  T normal_hi[3];
  T normal_lo[3];
};

/// Per-vertex outputs, #V entries each (d1, d2: 3 per vertex, row-major as RowMatrixX3d).
template <class T>
struct VertexFitOutput {
  T* k1;
  T* k2;
  T* H;
  T* K;
  T* d1;
  T* d2;
  T* residual;
  std::uint8_t* point_class;  ///< PointClass codes
  int* rays_used;
  int* rays_excluded;
};

/// The one parameter struct of the kernel (plain data, shared by host and device).
template <class T>
struct VertexFitParams {
  const VertexRecord<T>* vertices;  ///< #V, positions already multiplied by 1 / length_unit
  const int* offsets;               ///< CSR of the neighbourhoods (#V + 1)
  const int* indices;
  int vertex_count;
  bool gaussian;                ///< Gaussian weights; else uniform
  T inverse_two_width_squared;  ///< Gaussian weights exp(-d^2 * this), d in scaled units
  T curvature_unit;             ///< 1 / length_unit: k = (eigenvalue of W) x this (exact)
  T zero_tolerance;             ///< |k| at or below this is zero (absolute curvature)
  T umbilic_tolerance;          ///< relative gap at or below this is umbilic
  T min_relative_determinant;   ///< det / (trace/3)^3 at or below this: undefined
  VertexFitOutput<T> out;
};

using kernels::dot;
using kernels::Frame;
using kernels::Vec3;

/// hi + lo of `a` minus hi + lo of `b`: the hi difference first, which is exact to rounding
/// relative to itself, then the small correction.
template <class T>
FOCAL_HD inline Vec3<T> pair_difference(const T* a_hi, const T* a_lo, const T* b_hi,
                                        const T* b_lo) {
  return {(a_hi[0] - b_hi[0]) + (a_lo[0] - b_lo[0]), (a_hi[1] - b_hi[1]) + (a_lo[1] - b_lo[1]),
          (a_hi[2] - b_hi[2]) + (a_lo[2] - b_lo[2])};
}

/// A neighbour's ray (paper eq. 3) and its squared distance, in scaled units.
template <class T>
struct Ray {
  T sigma, tau, u, v, distance_squared;
};

/// The ray of neighbour `q` seen from vertex `p` in `f` (kernels::normal_ray, slopes by one
/// reciprocal as the CPU's lane kernel); false where the CPU has none (normal outside the open
/// hemisphere of n, or anything not finite; invalid normals are NaN).
template <class T>
FOCAL_HD inline bool ray_of(const Frame<T>& f, const VertexRecord<T>& p, const VertexRecord<T>& q,
                            Ray<T>& r) {
  const Vec3<T> m{q.normal_hi[0], q.normal_hi[1], q.normal_hi[2]};
  // The hemisphere test (normal_ray's too) before the pairs are loaded: a thread whose ray does
  // not exist reads nothing more, and the kernel keeps 56 registers (59 without, sm_90).
  if (!(dot(f.n, m) > T(0))) return false;
  const Vec3<T> d = pair_difference(q.normal_hi, q.normal_lo, p.normal_hi, p.normal_lo);
  const Vec3<T> o = pair_difference(q.position_hi, q.position_lo, p.position_hi, p.position_lo);
  r.distance_squared = dot(o, o);
  return kernels::normal_ray<kernels::Quotient::reciprocal>(f, o, m, d, r);
}

template <class T>
FOCAL_HD inline T ray_weight(const VertexFitParams<T>& p, const Ray<T>& r) {
  return p.gaussian ? std::exp(-r.distance_squared * p.inverse_two_width_squared) : T(1);
}

template <class T>
FOCAL_HD inline void store_undefined(const VertexFitOutput<T>& o, int i) {
  const T nan = static_cast<T>(NAN);  // numeric_limits is not callable in device code
  o.k1[i] = o.k2[i] = o.H[i] = o.K[i] = o.residual[i] = nan;
  for (int c = 0; c < 3; ++c) o.d1[3LL * i + c] = o.d2[3LL * i + c] = nan;
  o.point_class[i] = static_cast<std::uint8_t>(PointClass::undefined);
}

/// Weighted sum of squared misfits |W x - g|^2 and of the weights: a second pass over the
/// neighbours, since expanding E through the normal equations cancels catastrophically (it is 0
/// on a sphere). The rays are recomputed: cheaper on a GPU than keeping a ring in local memory.
template <class T>
FOCAL_HD inline void misfit(const VertexFitParams<T>& p, int i, const Frame<T>& f,
                            const kernels::SlitSolution<T>& w, T& energy, T& weight_sum) {
  energy = weight_sum = T(0);
  const VertexRecord<T>& me = p.vertices[i];
  for (int k = p.offsets[i]; k < p.offsets[i + 1]; ++k) {
    Ray<T> r;
    if (!ray_of(f, me, p.vertices[p.indices[k]], r)) continue;
    const T wt = ray_weight(p, r);
    energy += wt * kernels::slit_misfit(w, r.u, r.v, r.sigma, r.tau);
    weight_sum += wt;
  }
}

/// The whole fit of vertex i: writes every output field of row i.
template <class T>
FOCAL_HD inline void fit_vertex(const VertexFitParams<T>& p, int i) {
  const VertexFitOutput<T>& o = p.out;
  const VertexRecord<T>& me = p.vertices[i];
  const Vec3<T> n{me.normal_hi[0], me.normal_hi[1], me.normal_hi[2]};
  o.rays_used[i] = o.rays_excluded[i] = 0;
  if (!std::isfinite(n.x + n.y + n.z)) return store_undefined(o, i);
  const Frame<T> f = kernels::frame_of(n);
  kernels::SlitSums<T> sums;
  int used = 0, excluded = 0, weighted = 0;
  for (int k = p.offsets[i]; k < p.offsets[i + 1]; ++k) {
    Ray<T> r;
    if (!ray_of(f, me, p.vertices[p.indices[k]], r)) {
      ++excluded;
      continue;
    }
    ++used;
    const T w = ray_weight(p, r);
    if (!(w > T(0))) continue;  // as the CPU: a zero weight is no equation
    kernels::add_ray(sums, w, r.u, r.v, r.sigma, r.tau);
    ++weighted;
  }
  o.rays_used[i] = used;
  o.rays_excluded[i] = excluded;
  const kernels::SlitSolution<T> w = kernels::solve_slits(sums, p.min_relative_determinant);
  if (weighted < 2 || !w.valid) return store_undefined(o, i);
  T energy, weight_sum;
  misfit(p, i, f, w, energy, weight_sum);
  // Both divisions by a reciprocal, as the CPU's lane kernel.
  const kernels::Principal<T> e =
      kernels::principal_axes<kernels::Quotient::reciprocal, kernels::Quotient::reciprocal>(
          w.a, w.b, w.c);
  const T k1 = e.k1 * p.curvature_unit, k2 = e.k2 * p.curvature_unit;
  o.k1[i] = k1;
  o.k2[i] = k2;
  o.H[i] = T(0.5) * (k1 + k2);
  o.K[i] = k1 * k2;
  kernels::store3(o.d1 + 3LL * i, f.from_plane(e.d1x, e.d1y));
  kernels::store3(o.d2 + 3LL * i, f.from_plane(-e.d1y, e.d1x));
  o.residual[i] = std::sqrt(energy / weight_sum);
  o.point_class[i] = kernels::classify(k1, k2, p.zero_tolerance, p.umbilic_tolerance);
}

}  // namespace focal::cuda
