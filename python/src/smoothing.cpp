// focal.smooth: the bindings of focal::smooth (focal/smoothing/smooth.h).
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

#include <cmath>
#include <optional>

#include "bindings.h"
#include "focal/smoothing/smooth.h"

namespace focal_python {

using namespace nb::literals;

namespace {

nb::dict smooth(const DoubleRows& V, const std::optional<IntRows>& F,
                const std::optional<DoubleRows>& N, int iterations, int rings, int k,
                bool keep_creases, double crease_angle_degrees, bool robust, int threads) {
  focal::SmoothOptions o;
  o.iterations = iterations;
  o.rings = rings;
  o.neighbours = k;
  o.keep_creases = keep_creases;
  o.crease_angle = crease_angle_degrees * M_PI / 180.0;
  o.robust = robust;
  o.execution.threads = threads;
  focal::SmoothResult r;
  {
    nb::gil_scoped_release release;
    const focal::RowMatrixX3i no_faces(0, 3);
    const focal::PreparedMesh mesh(view(V),
                                   F ? focal::FacesRef(view(*F)) : focal::FacesRef(no_faces),
                                   N ? std::optional<focal::NormalsRef>(view(*N)) : std::nullopt);
    r = focal::smooth(mesh, o);
  }
  nb::dict d;
  d["V"] = to_numpy(std::move(r.V));
  d["N"] = to_numpy(std::move(r.N));
  d["iterations"] = r.iterations;
  nb::list noise;
  for (const double x : r.noise) noise.append(x);
  d["noise"] = noise;
  d["rings"] = r.rings;
  d["neighbours"] = r.neighbours;
  d["outliers_moved"] = r.outliers_moved;
  d["crease_points"] = r.crease_points;
  d["crease"] = to_numpy(std::move(r.crease));
  d["unfitted"] = r.unfitted;
  return d;
}

}  // namespace

void bind_smoothing(nb::module_& m) {
  m.def("smooth", &smooth, "V"_a.noconvert(), "F"_a.none().noconvert(), "N"_a.none().noconvert(),
        "iterations"_a, "rings"_a, "k"_a, "keep_creases"_a, "crease_angle"_a, "robust"_a,
        "threads"_a);
}

}  // namespace focal_python
