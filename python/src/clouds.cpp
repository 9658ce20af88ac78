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

#include "bindings.h"
#include "focal/core/error.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/normals/cloud_normals.h"

namespace focal_python {
namespace {

using namespace nb::literals;

focal::CloudOptions cloud_options(int k, double radius, double adaptive_radius,
                                  const std::string& normal_method,
                                  const std::optional<std::vector<double>>& viewpoint,
                                  const std::string& solver, int threads) {
  focal::CloudOptions o;
  o.k = k;
  o.radius = radius;
  o.adaptive_radius = adaptive_radius;
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
                         double radius, double adaptive_radius, const std::string& normal_method,
                         const std::optional<std::vector<double>>& viewpoint,
                         const std::string& solver, double outlier_ratio, int threads) {
  focal::CloudOptions o =
      cloud_options(k, radius, adaptive_radius, normal_method, viewpoint, solver, threads);
  o.outlier_ratio = outlier_ratio;
  focal::CloudCurvature c;
  {
    nb::gil_scoped_release release;
    c = N ? focal::estimate_cloud_curvature(view(V), focal::NormalsRef(view(*N)), o)
          : focal::estimate_cloud_curvature(view(V), std::nullopt, o);
  }
  nb::dict d = curvature_dict(std::move(c.curvature));
  d["N"] = to_numpy(std::move(c.N));
  return d;
}

nb::object cloud_normals(const DoubleRows& V, int k, double radius, double adaptive_radius,
                         const std::string& normal_method,
                         const std::optional<std::vector<double>>& viewpoint, int threads) {
  const focal::CloudOptions o =
      cloud_options(k, radius, adaptive_radius, normal_method, viewpoint, "closed-form", threads);
  focal::RowMatrixX3d N;
  {
    nb::gil_scoped_release release;
    focal::CloudNormalOptions normals = o.normals;
    normals.threads = threads;
    N = focal::cloud_normals(view(V), focal::cloud_neighbourhoods(view(V), o), normals);
  }
  return nb::cast(to_numpy(std::move(N)));
}

}  // namespace

void bind_clouds(nb::module_& m) {
  m.def("cloud_curvature", &cloud_curvature, "V"_a.noconvert(), "N"_a.none().noconvert(), "k"_a,
        "radius"_a, "adaptive_radius"_a, "normal_method"_a, "viewpoint"_a.none(), "solver"_a,
        "outlier_ratio"_a, "threads"_a);
  m.def("cloud_normals", &cloud_normals, "V"_a.noconvert(), "k"_a, "radius"_a, "adaptive_radius"_a,
        "normal_method"_a, "viewpoint"_a.none(), "threads"_a);
}

}  // namespace focal_python
