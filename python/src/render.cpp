// focal.render and focal.rasterise_gbuffer: pictures of per-vertex fields and G-buffers through
// focal::render (headless EGL; docs/RENDER.md). Without an OpenGL context the library throws
// RenderError, a DeviceError, which reaches Python as focal.DeviceError with its message.

#include "focal/render/render.h"

#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "bindings.h"
#include "focal/core/fields.h"

namespace focal_python {
namespace {

using namespace nb::literals;

using DoubleVector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using ByteVector = nb::ndarray<const std::uint8_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

Eigen::Vector3d vector3(const nb::handle& v) {
  const auto a = nb::cast<std::vector<double>>(v);
  if (a.size() != 3) throw focal::InvalidInput("a camera vector must have 3 numbers");
  return {a[0], a[1], a[2]};
}

/// The camera of the keywords of focal.render: look_at when `eye` is given, else fitted to V
/// from the orbit view.
focal::Camera camera(focal::PositionsRef V, const nb::dict& c) {
  const focal::Projection projection = nb::cast<bool>(c["orthographic"])
                                           ? focal::Projection::orthographic
                                           : focal::Projection::perspective;
  if (!c["eye"].is_none()) {
    focal::Camera cam = focal::look_at(vector3(c["eye"]), vector3(c["target"]), vector3(c["up"]));
    cam.projection = projection;
    cam.field_of_view = nb::cast<double>(c["field_of_view"]);
    if (!c["half_extent"].is_none()) cam.half_extent = nb::cast<double>(c["half_extent"]);
    return cam;
  }
  const focal::OrbitView view{.azimuth = nb::cast<double>(c["azimuth"]),
                              .elevation = nb::cast<double>(c["elevation"]),
                              .projection = projection,
                              .field_of_view = nb::cast<double>(c["field_of_view"]),
                              .margin = nb::cast<double>(c["margin"])};
  return focal::fit_camera(V, view);
}

focal::FocalMesh focal_mesh(const DoubleRows& V, const IntRows& F, const ByteVector& flag) {
  focal::FocalMesh m;
  m.mesh.V = view(V);
  m.mesh.F = view(F);
  m.flag =
      Eigen::Map<const focal::VectorXu8>(flag.data(), static_cast<Eigen::Index>(flag.shape(0)));
  return m;
}

nb::ndarray<nb::numpy, std::uint8_t> render(const DoubleRows& V, const IntRows& F,
                                            const DoubleRows& N, const DoubleVector& field,
                                            const nb::dict& o,
                                            const std::optional<DoubleRows>& directions,
                                            const std::optional<nb::tuple>& gammas,
                                            const std::optional<nb::bytes>& path_bytes) {
  const std::optional<std::string> path =
      path_bytes ? std::optional<std::string>(path_of(*path_bytes)) : std::nullopt;
  static const std::pair<const char*, focal::ColourMap> maps[] = {
      {"diverging", focal::ColourMap::diverging}, {"classes", focal::ColourMap::classes}};
  focal::FieldPictureOptions p;
  p.width = nb::cast<int>(o["width"]);
  p.height = nb::cast<int>(o["height"]);
  p.colour_map = parse_enum(nb::cast<std::string>(o["colour_map"]), "colour_map", maps);
  if (!o["range"].is_none()) {
    const auto r = nb::cast<std::pair<double, double>>(o["range"]);
    p.range = focal::ColourRange{r.first, r.second};
  }
  p.range_percentile = nb::cast<double>(o["range_percentile"]);
  p.title = nb::cast<std::string>(o["title"]);
  p.glyph_count = nb::cast<int>(o["glyph_count"]);
  p.splat_radius = nb::cast<double>(o["splat_radius"]);
  p.samples = nb::cast<int>(o["samples"]);
  if (directions) p.directions = view(*directions);
  if (gammas) {
    const nb::tuple& g = *gammas;
    p.focal_meshes = focal::FocalMeshes{
        focal_mesh(nb::cast<DoubleRows>(g[0]), nb::cast<IntRows>(g[1]), nb::cast<ByteVector>(g[2])),
        focal_mesh(nb::cast<DoubleRows>(g[3]), nb::cast<IntRows>(g[4]),
                   nb::cast<ByteVector>(g[5]))};
  }
  const Eigen::Map<const Eigen::VectorXd> values(field.data(),
                                                 static_cast<Eigen::Index>(field.shape(0)));
  // The camera reads the keywords (Python objects): with the GIL held.
  p.camera = camera(view(V), o);
  const int threads = nb::cast<int>(o["threads"]);
  focal::Image image;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope({.threads = threads});
    image = focal::render_field_picture(view(V), view(F), view(N), values, p);
    if (path) focal::write_png(*path, image);
  }
  return pixels(std::move(image.rgb), image.height, image.width, 3);
}

nb::dict rasterise_gbuffer(const DoubleRows& V, const IntRows& F, const DoubleRows& N,
                           const nb::dict& o) {
  const int width = nb::cast<int>(o["width"]);
  const int height = nb::cast<int>(o["height"]);
  focal::GBuffer g;
  const focal::Camera cam = camera(view(V), o);  // reads the keywords: with the GIL held
  {
    nb::gil_scoped_release release;
    g = focal::rasterise_gbuffer(view(V), view(F), view(N), cam, width, height);
  }
  nb::dict d;
  d["position"] = pixels(std::move(g.position), height, width, 3);
  d["normal"] = pixels(std::move(g.normal), height, width, 3);
  d["mask"] = pixels(std::move(g.mask), height, width, 1);
  d["eye"] = nb::make_tuple(cam.eye.x(), cam.eye.y(), cam.eye.z());
  return d;
}

}  // namespace

void bind_render(nb::module_& m) {
  m.def("render", &render, "V"_a.noconvert(), "F"_a.noconvert(), "N"_a.noconvert(),
        "field"_a.noconvert(), "options"_a, "directions"_a.none().noconvert(), "gammas"_a.none(),
        "path"_a.none());
  m.def("rasterise_gbuffer", &rasterise_gbuffer, "V"_a.noconvert(), "F"_a.noconvert(),
        "N"_a.noconvert(), "options"_a);
}

}  // namespace focal_python
