// focal.image_space_curvature and focal.ImageCurvatureContext: the paper's image-space estimator
// (section 5.1) on a G-buffer of NumPy arrays, on the CPU or a GPU, one-shot or frame after frame
// (focal/image_space/image_space.h; docs/IMAGE_SPACE.md).

#include "focal/image_space/image_space.h"

#include <nanobind/stl/optional.h>

#include "bindings.h"

namespace focal_python {
namespace {

using namespace nb::literals;

using FloatPixels = nb::ndarray<const float, nb::c_contig, nb::device::cpu>;
using BytePixels = nb::ndarray<const std::uint8_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

/// The Python layer checked the shapes: position, normal (h, w, 3) float32, mask (h, w) uint8.
/// The GBuffer owns its vectors, so the inputs are copied once into it.
focal::GBuffer gbuffer_of(const FloatPixels& position, const FloatPixels& normal,
                          const BytePixels& mask) {
  focal::GBuffer g;
  g.height = static_cast<int>(mask.shape(0));
  g.width = static_cast<int>(mask.shape(1));
  g.position.assign(position.data(), position.data() + position.size());
  g.normal.assign(normal.data(), normal.data() + normal.size());
  g.mask.assign(mask.data(), mask.data() + mask.size());
  return g;
}

/// The fields as (h, w) and (h, w, 3) arrays that own the result's vectors.
nb::dict fields_of(focal::ImageCurvature&& c) {
  const int h = c.height, w = c.width;
  nb::dict d;
  d["k1"] = pixels(std::move(c.k1), h, w, 1);
  d["k2"] = pixels(std::move(c.k2), h, w, 1);
  d["H"] = pixels(std::move(c.H), h, w, 1);
  d["K"] = pixels(std::move(c.K), h, w, 1);
  d["focal_depth1"] = pixels(std::move(c.focal_depth1), h, w, 1);
  d["focal_depth2"] = pixels(std::move(c.focal_depth2), h, w, 1);
  d["d1"] = pixels(std::move(c.d1), h, w, 3);
  d["d2"] = pixels(std::move(c.d2), h, w, 3);
  d["valid"] = pixels(std::move(c.valid), h, w, 1);
  return d;
}

nb::dict image_space_curvature(const FloatPixels& position, const FloatPixels& normal,
                               const BytePixels& mask, double discontinuity_ratio, int window,
                               int threads, std::optional<int> device) {
  const focal::GBuffer g = gbuffer_of(position, normal, mask);
  const focal::ImageSpaceOptions o{.discontinuity_ratio = discontinuity_ratio, .window = window};
  focal::ImageCurvature c;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope({.threads = threads});
    c = device ? focal::estimate_image_curvature_cuda(g, o, *device)
               : focal::estimate_image_curvature(g, o);
  }
  return fields_of(std::move(c));
}

void new_context(focal::ImageCurvatureCudaContext* self, int width, int height,
                 double discontinuity_ratio, int window, int device) {
  const focal::ImageSpaceOptions o{.discontinuity_ratio = discontinuity_ratio, .window = window};
  new (self) focal::ImageCurvatureCudaContext(width, height, o, device);
}

nb::dict context_estimate(focal::ImageCurvatureCudaContext& context, const FloatPixels& position,
                          const FloatPixels& normal, const BytePixels& mask) {
  const focal::GBuffer g = gbuffer_of(position, normal, mask);
  focal::ImageCurvature c;
  {
    nb::gil_scoped_release release;
    context.estimate(g, c);
  }
  return fields_of(std::move(c));
}

}  // namespace

void bind_image_space(nb::module_& m) {
  m.def("image_space_curvature", &image_space_curvature, "position"_a.noconvert(),
        "normal"_a.noconvert(), "mask"_a.noconvert(), "discontinuity_ratio"_a, "window"_a,
        "threads"_a, "device"_a.none());
  nb::class_<focal::ImageCurvatureCudaContext>(m, "ImageCurvatureCudaContext")
      .def("__init__", &new_context, "width"_a, "height"_a, "discontinuity_ratio"_a, "window"_a,
           "device"_a)
      .def("estimate", &context_estimate, "position"_a.noconvert(), "normal"_a.noconvert(),
           "mask"_a.noconvert());
}

}  // namespace focal_python
