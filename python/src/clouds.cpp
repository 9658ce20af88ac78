// Point clouds in focal._focal_ext: cloud_curvature and cloud_normals over the library's
// focal/curvature/cloud_curvature.h and focal/normals/cloud_normals.h, registered by
// bind_clouds(m) from focal_ext.cpp. Inputs arrive as focal_ext.cpp's do (C-ordered float64
// n x 3, checked and converted once by python/focal/_clouds.py); results are NumPy arrays that
// own the library's buffers; the GIL is released while the library computes. Errors are
// translated by focal_ext.cpp's translator (focal::InvalidInput -> InvalidInputError).

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "focal/core/error.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/normals/cloud_normals.h"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using DoubleRows = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using ConstMapX3d = Eigen::Map<const focal::RowMatrixX3d>;

ConstMapX3d view(const DoubleRows& a) {
  return ConstMapX3d(a.data(), static_cast<Eigen::Index>(a.shape(0)), 3);
}

/// A result moved to the heap and handed to NumPy, which frees it through the capsule.
template <class Matrix>
nb::object owned_array(Matrix&& m) {
  using M = std::decay_t<Matrix>;
  auto* owned = new M(std::forward<Matrix>(m));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<M*>(p); });
  const size_t shape[2] = {static_cast<size_t>(owned->rows()), static_cast<size_t>(owned->cols())};
  return nb::cast(nb::ndarray<nb::numpy, typename M::Scalar>(
      owned->data(), M::ColsAtCompileTime == 1 ? 1 : 2, shape, owner));
}

focal::CloudOptions cloud_options(int k, double radius, const std::string& normal_method,
                                  const std::optional<std::vector<double>>& viewpoint,
                                  const std::string& solver, int threads) {
  focal::CloudOptions o;
  o.k = k;
  o.radius = radius;
  o.threads = threads;
  if (normal_method == "jet") {
    o.normals.method = focal::CloudNormalMethod::jet;
  } else if (normal_method == "pca") {
    o.normals.method = focal::CloudNormalMethod::pca;
  } else {
    throw focal::InvalidInput("normal_method must be 'jet' or 'pca', got '" + normal_method + "'");
  }
  if (solver == "closed-form") {
    o.solver = focal::Solver::closed_form;
  } else if (solver == "levenberg-marquardt") {
    o.solver = focal::Solver::levenberg_marquardt;
  } else {
    throw focal::InvalidInput("solver must be 'closed-form' or 'levenberg-marquardt', got '" +
                              solver + "'");
  }
  if (viewpoint) {
    if (viewpoint->size() != 3) throw focal::InvalidInput("viewpoint must be 3 numbers (x, y, z)");
    o.normals.viewpoint = Eigen::Vector3d((*viewpoint)[0], (*viewpoint)[1], (*viewpoint)[2]);
  }
  return o;
}

nb::dict cloud_curvature(const DoubleRows& V, const std::optional<DoubleRows>& N, int k,
                         double radius, const std::string& normal_method,
                         const std::optional<std::vector<double>>& viewpoint,
                         const std::string& solver, int threads) {
  const focal::CloudOptions o = cloud_options(k, radius, normal_method, viewpoint, solver, threads);
  focal::CloudCurvature c;
  {
    nb::gil_scoped_release release;
    c = N ? focal::estimate_cloud_curvature(view(V), focal::NormalsRef(view(*N)), o)
          : focal::estimate_cloud_curvature(view(V), std::nullopt, o);
  }
  focal::CurvatureResult& r = c.curvature;
  nb::dict d;
  d["k1"] = owned_array(std::move(r.k1));
  d["k2"] = owned_array(std::move(r.k2));
  d["H"] = owned_array(std::move(r.H));
  d["K"] = owned_array(std::move(r.K));
  d["d1"] = owned_array(std::move(r.d1));
  d["d2"] = owned_array(std::move(r.d2));
  d["residual"] = owned_array(std::move(r.residual));
  d["point_class"] = owned_array(std::move(r.point_class));
  d["rays_used"] = owned_array(std::move(r.rays_used));
  d["rays_excluded"] = owned_array(std::move(r.rays_excluded));
  d["N"] = owned_array(std::move(c.N));
  return d;
}

nb::object cloud_normals(const DoubleRows& V, int k, double radius,
                         const std::string& normal_method,
                         const std::optional<std::vector<double>>& viewpoint, int threads) {
  const focal::CloudOptions o =
      cloud_options(k, radius, normal_method, viewpoint, "closed-form", threads);
  focal::RowMatrixX3d N;
  {
    nb::gil_scoped_release release;
    focal::CloudNormalOptions normals = o.normals;
    normals.threads = threads;
    N = focal::cloud_normals(view(V), focal::cloud_neighbourhoods(view(V), o), normals);
  }
  return owned_array(std::move(N));
}

}  // namespace

void bind_clouds(nb::module_& m) {
  m.def("cloud_curvature", &cloud_curvature, "V"_a.noconvert(), "N"_a.none().noconvert(), "k"_a,
        "radius"_a, "normal_method"_a, "viewpoint"_a.none(), "solver"_a, "threads"_a);
  m.def("cloud_normals", &cloud_normals, "V"_a.noconvert(), "k"_a, "radius"_a, "normal_method"_a,
        "viewpoint"_a.none(), "threads"_a);
}
