#pragma once
// The per-face body of the CUDA per-triangle estimator (src/cuda/triangle_fit.cu) in plain data,
// so that the CPU runs exactly the same code (cuda/triangle_fit.cpp: triangle_curvature_float) and
// tests compare it with triangle_curvature in double: the characteristic equation of
// kernels/triplet.h, the one triangle_curvature runs, in float.

#include <cstdint>

#include "kernels/local_shape.h"
#include "kernels/triplet.h"
#include "kernels/vec3.h"

namespace focal::triangle_kernel {

using kernels::Vec3;

/// Per-face float outputs, field-major: value (field, face) at field * faces + face.
namespace field {
constexpr int A = 0, B = 1, C = 2, K = 3, H = 4, k1 = 5, k2 = 6, lambda1 = 7, lambda2 = 8;
constexpr int d1 = 9, d2 = 12, slit1 = 15, slit2 = 18, face_normal = 21;  ///< 3 each
constexpr int shape_operator = 24;                                        ///< 4: m00, m01, m10, m11
constexpr int count = 28;
}  // namespace field

struct TriangleKernelParams {
  const double* V = nullptr;        ///< 3 per vertex
  const double* N = nullptr;        ///< 3 per vertex, any length
  const std::int32_t* F = nullptr;  ///< 3 per face, indices already checked against V
  int faces = 0;
  float zero_tolerance = 0.0f;  ///< absolute, as detail::class_tolerances
  float umbilic_tolerance = 0.0f;
  float* values = nullptr;              ///< field::count x faces
  std::uint8_t* point_class = nullptr;  ///< faces
};

/// Face f's triplet: positions relative to the face's centroid in double (a float mesh far from
/// the origin would lose its edge lengths to rounding), then the characteristic equation in float.
FOCAL_HD inline triplet::TripletSolution<float> face_triplet(const TriangleKernelParams& k, int f) {
  Vec3<double> p[3], centroid{0.0, 0.0, 0.0};
  for (int c = 0; c < 3; ++c) {
    p[c] = kernels::load3(k.V + 3LL * k.F[3LL * f + c]);
    centroid = centroid + p[c];
  }
  centroid = (1.0 / 3.0) * centroid;
  Vec3<float> q[3], n[3];
  for (int c = 0; c < 3; ++c) {
    q[c] = kernels::vec_cast<float>(p[c] - centroid);
    n[c] = kernels::vec_cast<float>(kernels::load3(k.N + 3LL * k.F[3LL * f + c]));
  }
  return triplet::solve_triplet(q, n);
}

/// Where value (field, face) lives; 64-bit, as field::count x faces may exceed int.
FOCAL_HD inline float& value_at(const TriangleKernelParams& k, int field_index, int f) {
  return k.values[static_cast<long long>(field_index) * k.faces + f];
}

FOCAL_HD inline void store_field3(const TriangleKernelParams& k, int offset, int f, Vec3<float> v) {
  value_at(k, offset, f) = v.x;
  value_at(k, offset + 1, f) = v.y;
  value_at(k, offset + 2, f) = v.z;
}

/// Solves face f and writes its outputs (NaN and `undefined` where it has none).
FOCAL_HD inline void triangle_face(const TriangleKernelParams& k, int f) {
  const triplet::TripletSolution<float> s = face_triplet(k, f);
  const float scalars[9] = {s.A, s.B, s.C, s.K, s.H, s.k1, s.k2, s.lambda1, s.lambda2};
  for (int i = 0; i < 9; ++i) value_at(k, i, f) = scalars[i];
  store_field3(k, field::d1, f, s.d1);
  store_field3(k, field::d2, f, s.d2);
  store_field3(k, field::slit1, f, s.slit1);
  store_field3(k, field::slit2, f, s.slit2);
  store_field3(k, field::face_normal, f, s.frame.n);
  const float m[4] = {s.shape.a, s.shape.b, s.shape.c, s.shape.d};
  for (int i = 0; i < 4; ++i) value_at(k, field::shape_operator + i, f) = m[i];
  k.point_class[f] = s.valid ? kernels::classify(s.k1, s.k2, k.zero_tolerance, k.umbilic_tolerance)
                             : kernels::class_code<float>(PointClass::undefined);
}

}  // namespace focal::triangle_kernel
