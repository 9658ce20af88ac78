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

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "focal/core/error.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/normals/cloud_normals.h"
#include "focal/tiles/tiles.h"

namespace focal_python {
namespace {

using namespace nb::literals;

focal::CloudOptions cloud_options(int k, double radius, double adaptive_radius,
                                  const std::string& normal_method,
                                  const std::optional<std::vector<double>>& viewpoint,
                                  const std::string& solver, const std::string& orient = "mst") {
  focal::CloudOptions o;
  o.k = k;
  o.radius = radius;
  o.adaptive_radius = adaptive_radius;
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
  if (orient == "mst") {
    o.normals.orientation = focal::CloudOrientation::mst;
  } else if (orient == "global") {
    o.normals.orientation = focal::CloudOrientation::global;
  } else if (orient == "viewpoint") {
    o.normals.orientation = focal::CloudOrientation::viewpoint;
  } else {
    throw focal::InvalidInput("orient must be 'mst', 'global' or 'viewpoint', got '" + orient +
                              "'");
  }
  return o;
}

nb::dict cloud_curvature(const DoubleRows& V, const std::optional<DoubleRows>& N, int k,
                         double radius, double adaptive_radius, const std::string& normal_method,
                         const std::optional<std::vector<double>>& viewpoint,
                         const std::string& solver, double outlier_ratio, double off_surface_ratio,
                         const std::string& orient, int threads) {
  focal::CloudOptions o =
      cloud_options(k, radius, adaptive_radius, normal_method, viewpoint, solver, orient);
  o.outlier_ratio = outlier_ratio;
  o.off_surface_ratio = off_surface_ratio;
  o.keep_neighbours = false;  // not returned
  focal::CloudCurvature c;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope({.threads = threads});
    c = N ? focal::estimate_cloud_curvature(view(V), focal::NormalsRef(view(*N)), o)
          : focal::estimate_cloud_curvature(view(V), std::nullopt, o);
  }
  nb::dict d = curvature_dict(std::move(c.curvature));
  d["N"] = to_numpy(std::move(c.N));
  return d;
}

nb::object cloud_normals(const DoubleRows& V, int k, double radius, double adaptive_radius,
                         const std::string& normal_method,
                         const std::optional<std::vector<double>>& viewpoint,
                         const std::string& orient, int threads) {
  const focal::CloudOptions o =
      cloud_options(k, radius, adaptive_radius, normal_method, viewpoint, "closed-form", orient);
  focal::RowMatrixX3d N;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope({.threads = threads});
    // What `focal normals` runs on a cloud: the default's plan for k = 0, else those neighbours.
    N = focal::estimate_cloud_normals(view(V), std::nullopt, o);
  }
  return nb::cast(to_numpy(std::move(N)));
}

// ---- A cloud in tiles (focal/tiles/tiles.h), for python/focal/distributed.py ----------------

}  // namespace

focal::CloudOptions cloud_options_from(const nb::dict& d) {
  const auto viewpoint = d["viewpoint"].is_none() ? std::optional<std::vector<double>>()
                                                  : nb::cast<std::vector<double>>(d["viewpoint"]);
  const double adaptive_radius =
      d.contains("adaptive_radius") ? nb::cast<double>(d["adaptive_radius"]) : 0.0;
  focal::CloudOptions o = cloud_options(
      nb::cast<int>(d["k"]), nb::cast<double>(d["radius"]), adaptive_radius,
      nb::cast<std::string>(d["normal_method"]), viewpoint, nb::cast<std::string>(d["solver"]),
      d.contains("orient") ? nb::cast<std::string>(d["orient"]) : std::string("mst"));
  o.outlier_ratio = nb::cast<double>(d["outlier_ratio"]);
  o.off_surface_ratio = nb::cast<double>(d["off_surface_ratio"]);
  return o;
}

namespace {

/// cloud_curvature's arguments as one dict (what a tile task carries).
focal::CloudOptions cloud_options_of(const nb::dict& d) {
  focal::CloudOptions o = cloud_options_from(d);
  focal::require_tileable(o);
  return o;
}

using Flags = nb::ndarray<const std::uint8_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

std::vector<char> flags_from(const std::optional<Flags>& a) {
  if (!a) return {};
  return {a->data(), a->data() + a->shape(0)};
}

nb::object flags_to_numpy(const std::vector<char>& flags) {
  if (flags.empty()) return nb::none();
  Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 1> v(static_cast<Eigen::Index>(flags.size()));
  for (std::size_t i = 0; i < flags.size(); ++i) v[static_cast<Eigen::Index>(i)] = flags[i];
  return nb::cast(to_numpy(std::move(v)));
}

/// The whole cloud's plan (plan_cloud_curvature): its choices, normals and outlier flags, and
/// its tiles (partition_cloud over the fit's neighbourhoods, depth 1).
nb::dict cloud_tile_plan(const DoubleRows& V, const std::optional<DoubleRows>& N,
                         const nb::dict& options, int tile_vertices) {
  const focal::CloudOptions o = cloud_options_of(options);
  const int threads = nb::cast<int>(options["threads"]);
  focal::CloudCurvature plan;
  focal::Tiling tiling;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope({.threads = threads});
    plan = N ? focal::plan_cloud_curvature(view(V), focal::NormalsRef(view(*N)), o)
             : focal::plan_cloud_curvature(view(V), std::nullopt, o);
    tiling = focal::partition_cloud(view(V), plan.neighbours, 1, {.tile_vertices = tile_vertices});
  }
  nb::list tiles;
  for (const focal::Tile& t : tiling.tiles) {
    nb::dict d;
    d["vertices"] = ids_to_numpy(t.vertices);
    d["owned"] = ids_to_numpy(t.owned);
    tiles.append(d);
  }
  nb::dict choices;
  choices["spacing"] = plan.spacing;
  choices["k"] = plan.k;
  choices["corrected"] = plan.corrected;
  nb::dict d;
  d["choices"] = choices;
  d["N"] = to_numpy(std::move(plan.N));
  d["outlier"] = flags_to_numpy(plan.outlier);
  d["tiles"] = tiles;
  return d;
}

nb::dict extract_cloud_tile(const DoubleRows& V, const DoubleRows& N,
                            const std::optional<Flags>& outlier, const Ids& vertices) {
  const focal::Tile tile{ids_from(vertices), {}, {}};
  focal::TileCloud t;
  {
    nb::gil_scoped_release release;
    t = focal::extract_cloud_tile(view(V), view(N), flags_from(outlier), tile);
  }
  nb::dict d;
  d["V"] = to_numpy(std::move(t.V));
  d["N"] = to_numpy(std::move(t.N));
  d["outlier"] = flags_to_numpy(t.outlier);
  return d;
}

/// The fit of every point of a cloud tile, with the whole cloud's choices.
nb::dict estimate_cloud_tile(const DoubleRows& V, const DoubleRows& N,
                             const std::optional<Flags>& outlier, const nb::dict& options,
                             const nb::dict& choices) {
  const focal::CloudOptions o = cloud_options_of(options);
  const focal::CloudWideChoices c{nb::cast<double>(choices["spacing"]), nb::cast<int>(choices["k"]),
                                  nb::cast<bool>(choices["corrected"])};
  const int threads = nb::cast<int>(options["threads"]);
  focal::TileEstimate r;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope({.threads = threads});
    const focal::TileCloud tile{view(V), view(N), flags_from(outlier)};
    r = focal::estimate_cloud_tile(tile, c, o);
  }
  return curvature_dict(std::move(r.curvature));
}

}  // namespace

void bind_clouds(nb::module_& m) {
  m.def("cloud_curvature", &cloud_curvature, "V"_a.noconvert(), "N"_a.none().noconvert(), "k"_a,
        "radius"_a, "adaptive_radius"_a, "normal_method"_a, "viewpoint"_a.none(), "solver"_a,
        "outlier_ratio"_a, "off_surface_ratio"_a, "orient"_a, "threads"_a);
  m.def("cloud_normals", &cloud_normals, "V"_a.noconvert(), "k"_a, "radius"_a, "adaptive_radius"_a,
        "normal_method"_a, "viewpoint"_a.none(), "orient"_a, "threads"_a);
  m.def("cloud_tile_plan", &cloud_tile_plan, "V"_a.noconvert(), "N"_a.none().noconvert(),
        "options"_a, "tile_vertices"_a);
  m.def("extract_cloud_tile", &extract_cloud_tile, "V"_a.noconvert(), "N"_a.noconvert(),
        "outlier"_a.none().noconvert(), "vertices"_a.noconvert());
  m.def("estimate_cloud_tile", &estimate_cloud_tile, "V"_a.noconvert(), "N"_a.noconvert(),
        "outlier"_a.none().noconvert(), "options"_a, "choices"_a);
}

}  // namespace focal_python
