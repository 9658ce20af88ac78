// Host side of the float per-triangle estimator (see cuda/triangle_fit.h).
#include "cuda/triangle_fit.h"

#include <string>
#include <utility>

#include "focal/core/error.h"
#include "focal/cuda/curvature.h"
#include "focal/cuda/device.h"

namespace focal::detail {

static_assert(triangle_kernel::field::count == 28);

TriangleInput triangle_input(PositionsRef V, FacesRef F, NormalsRef N,
                             const CurvatureOptions& options, const char* what) {
  if (N.rows() != V.rows()) {
    throw InvalidInput(std::string(what) + ": " + std::to_string(N.rows()) + " normals for " +
                       std::to_string(V.rows()) + " vertices");
  }
  validate_mesh_arrays(V, F, N, what);
  TriangleInput in;
  in.faces = static_cast<int>(F.rows());
  in.V.resize(3 * static_cast<std::size_t>(V.rows()));
  in.N.resize(in.V.size());
  in.F.resize(3 * static_cast<std::size_t>(F.rows()));
  // Row by row: the Refs may have an outer stride.
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    for (int c = 0; c < 3; ++c) in.V[3 * i + c] = V(i, c), in.N[3 * i + c] = N(i, c);
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) in.F[3 * f + c] = F(f, c);
  }
  // The thresholds of triangle_curvature (detail::class_tolerances), rounded to float.
  in.zero_tolerance = static_cast<float>(options.tolerances.zero / mean_edge_length(V, F));
  in.umbilic_tolerance = static_cast<float>(options.tolerances.umbilic);
  return in;
}

TriangleCurvatureResult triangle_result(const std::vector<float>& values,
                                        const std::vector<std::uint8_t>& classes, int faces) {
  namespace field = triangle_kernel::field;
  const auto at = [&](int f_index, Eigen::Index f) {
    return static_cast<double>(values[static_cast<std::size_t>(f_index) * faces + f]);
  };
  TriangleCurvatureResult r;
  Eigen::VectorXd* scalars[9] = {&r.A,  &r.B,  &r.C,       &r.K,      &r.H,
                                 &r.k1, &r.k2, &r.lambda1, &r.lambda2};
  for (int i = 0; i < 9; ++i) {
    scalars[i]->resize(faces);
    for (Eigen::Index f = 0; f < faces; ++f) (*scalars[i])[f] = at(i, f);
  }
  const std::pair<RowMatrixX3d*, int> vectors[5] = {{&r.d1, field::d1},
                                                    {&r.d2, field::d2},
                                                    {&r.slit1, field::slit1},
                                                    {&r.slit2, field::slit2},
                                                    {&r.face_normal, field::face_normal}};
  for (const auto& [m, offset] : vectors) {
    m->resize(faces, 3);
    for (Eigen::Index f = 0; f < faces; ++f) {
      for (int c = 0; c < 3; ++c) (*m)(f, c) = at(offset + c, f);
    }
  }
  r.shape_operator.resize(faces, 4);
  for (Eigen::Index f = 0; f < faces; ++f) {
    for (int c = 0; c < 4; ++c) r.shape_operator(f, c) = at(field::shape_operator + c, f);
  }
  r.point_class = Eigen::Map<const VectorXu8>(classes.data(), faces);
  return r;
}

TriangleCurvatureResult triangle_curvature_float(PositionsRef V, FacesRef F, NormalsRef N,
                                                 const CurvatureOptions& options) {
  const TriangleInput in = triangle_input(V, F, N, options, "triangle curvature (float)");
  std::vector<float> values(static_cast<std::size_t>(triangle_kernel::field::count) * in.faces);
  std::vector<std::uint8_t> classes(static_cast<std::size_t>(in.faces));
  const triangle_kernel::TriangleKernelParams k{
      in.V.data(),       in.N.data(),          in.F.data(),   in.faces,
      in.zero_tolerance, in.umbilic_tolerance, values.data(), classes.data()};
  for (int f = 0; f < in.faces; ++f) triangle_kernel::triangle_face(k, f);
  return triangle_result(values, classes, in.faces);
}

}  // namespace focal::detail

namespace focal {

TriangleCurvatureResult triangle_curvature_cuda(PositionsRef V, FacesRef F, NormalsRef N,
                                                const CurvatureOptions& options, int device) {
  (void)require_cuda_device(device);  // DeviceError first: without a device nothing else matters
  const detail::TriangleInput in =
      detail::triangle_input(V, F, N, options, "triangle_curvature_cuda");
  std::vector<float> values(static_cast<std::size_t>(triangle_kernel::field::count) * in.faces);
  std::vector<std::uint8_t> classes(static_cast<std::size_t>(in.faces));
  if (in.faces > 0) detail::triangle_faces_on_device(in, values, classes, device);
  return detail::triangle_result(values, classes, in.faces);
}

}  // namespace focal
