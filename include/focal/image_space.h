#pragma once
/// \file image_space.h
/// The paper's image-space estimator (section 5.1): positions and normals rasterised into float
/// images (a G-buffer); every pixel solves the characteristic equation of the normal rays of the
/// pixel triplet (x, y), (x + 1, y), (x, y + 1).
///
/// CONTRACT DRAFT (issue 7): the names below are what the render library and the CUDA backend
/// code against; the image-space work finalises the details and the documentation.

#include <cstdint>
#include <vector>

#include "focal/surfaces.h"

namespace focal {

/// Float images of one view, row-major, pixel (x, y) at index y * width + x; 3 floats per pixel
/// for position and normal.
struct GBuffer {
  int width = 0;
  int height = 0;
  std::vector<float> position;      ///< 3 per pixel, world coordinates
  std::vector<float> normal;        ///< 3 per pixel, unit outward normal
  std::vector<std::uint8_t> mask;   ///< 1 where a surface covers the pixel, else 0
};

struct ImageSpaceOptions {
  /// A triplet whose pixels are further apart in space than this many times the median pixel
  /// footprint counts as crossing a depth discontinuity: its pixel is invalid.
  double discontinuity_ratio = 4.0;
  /// Triplet averaging: the coefficients are averaged over a (2 w + 1)^2 window (0 = none).
  int window = 0;
  int threads = 0;  ///< 0: FOCAL_NUM_THREADS or all hardware threads
};

/// Per-pixel fields, width * height each; invalid pixels have NaN in every float field.
struct ImageCurvature {
  int width = 0;
  int height = 0;
  std::vector<float> k1, k2, H, K;
  std::vector<float> focal_depth1, focal_depth2;  ///< -1/k1, -1/k2 along the normal
  std::vector<float> d1, d2;                       ///< 3 per pixel, principal (slit) directions
  std::vector<std::uint8_t> valid;
};

/// CPU reference. \throw InvalidInput when the buffer's sizes disagree.
[[nodiscard]] ImageCurvature estimate_image_curvature(const GBuffer& gbuffer,
                                                      const ImageSpaceOptions& options = {});

/// The same on a CUDA device. \throw DeviceError without the CUDA backend or a device.
[[nodiscard]] ImageCurvature estimate_image_curvature_cuda(const GBuffer& gbuffer,
                                                           const ImageSpaceOptions& options = {},
                                                           int device = 0);

/// A geometry image: an analytic surface sampled on a regular width x height grid of its
/// parameter domain, with the exact truth per pixel alongside.
struct GeometryImage {
  GBuffer gbuffer;
  std::vector<float> k1, k2;  ///< exact principal curvatures per pixel
};
[[nodiscard]] GeometryImage geometry_image(const SurfaceOptions& surface, int width, int height);

}  // namespace focal
