#pragma once
// The two-slit fit in closed form (paper section 5, eqs. 10-14; include/focal/curvature/
// two_slit_fit.h derives it): with x_i = (u_i, v_i), g_i = (sigma_i, tau_i) and W = [a b; b c],
// minimise E = sum_i w_i |W x_i - g_i|^2, a linear least-squares problem in (a, b, c). The
// eigenvalues of W are k1, k2 (kernels/local_shape.h's principal_axes).
//
// The one copy of the fit's arithmetic, with three drivers: the scalar one in double
// (curvature/two_slit_detail.h: a vertex's rays, the closed form on them, the
// Levenberg-Marquardt solver's well-posedness test; the Levenberg-Marquardt and robust per-vertex
// fits), the CPU lane kernel of the closed-form per-vertex estimator (curvature/curvature.cpp,
// GCC vector types; tuned, with the bits of these formulas on scalar doubles) and the CUDA
// per-vertex kernel (kernels/vertex_fit.h, float, its data as float pairs). Templates on the
// element type of kernels/vec3.h; no branches on values, so lanes run the same source. Plain
// data: nvcc compiles this header.

#include "kernels/host_device.h"
#include "kernels/vec3.h"

namespace focal::kernels {

/// Sums of the normal equations over the rays. Their matrix is [[uu, uv, 0], [uv, uu + vv, uv],
/// [0, uv, vv]] (each ray gives the rows (u, v, 0) -> sigma and (0, u, v) -> tau), so three sums
/// describe it; (r0, r1, r2) is the right-hand side.
template <class T>
struct alignas(sizeof(T)) SlitSums {
  T uu{}, uv{}, vv{};
  T r0{}, r1{}, r2{};
};

/// Adds the ray (u, v, sigma, tau) with weight w. A weight of zero adds nothing, but the callers
/// skip such rays (and count the rays of positive weight: a fit needs two).
template <class T>
FOCAL_HD_INLINE void add_ray(SlitSums<T>& s, T w, T u, T v, T sigma, T tau) {
  s.uu += w * u * u;
  s.uv += w * u * v;
  s.vv += w * v * v;
  s.r0 += w * (u * sigma);
  s.r1 += w * (v * sigma + u * tau);
  s.r2 += w * (v * tau);
}

/// The fitted W = [a b; b c], and whether the fit is well posed.
template <class T>
struct alignas(sizeof(T)) SlitSolution {
  T a, b, c;
  /// The normal equations are well conditioned: det > min_relative_determinant (trace/3)^3, a
  /// test invariant to the scale of the mesh; and W is finite.
  Mask<T> valid;
};

/// Solves the normal equations by the cofactors of their matrix. `min_relative_determinant`:
/// 1e-12 in double; in float, see cuda/vertex_fit.h.
template <class T>
FOCAL_HD_INLINE SlitSolution<T> solve_slits(const SlitSums<T>& s,
                                            Element<T> min_relative_determinant) {
  using S = Element<T>;
  const T a = s.uu, b = s.uv, c = s.vv, t = a + c;
  const T c00 = t * c - b * b, c01 = -(b * c), c02 = b * b;
  const T c11 = a * c, c12 = -(a * b), c22 = a * t - b * b;
  const T det = a * c00 + b * c01;
  const T scale = (a + t + c) * (S(1) / S(3));
  const T inv_det = S(1) / det;
  SlitSolution<T> w;
  w.a = (c00 * s.r0 + c01 * s.r1 + c02 * s.r2) * inv_det;
  w.b = (c01 * s.r0 + c11 * s.r1 + c12 * s.r2) * inv_det;
  w.c = (c02 * s.r0 + c12 * s.r1 + c22 * s.r2) * inv_det;
  w.valid = (scale > S(0)) & (det > min_relative_determinant * scale * scale * scale) &
            is_finite(w.a) & is_finite(w.b) & is_finite(w.c);
  return w;
}

/// A ray's squared misfit |W x - g|^2 (the paper's E is its weighted sum), evaluated directly:
/// expanding E through the normal equations cancels catastrophically (it is 0 on a sphere).
template <class T>
FOCAL_HD_INLINE T slit_misfit(const SlitSolution<T>& w, T u, T v, T sigma, T tau) {
  const T ru = w.a * u + w.b * v - sigma;
  const T rv = w.b * u + w.c * v - tau;
  return ru * ru + rv * rv;
}

}  // namespace focal::kernels
