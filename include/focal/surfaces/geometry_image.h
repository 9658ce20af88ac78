#pragma once
/// \file geometry_image.h
/// Geometry images of the analytic surfaces: G-buffers with exact truth per pixel, on which the
/// image-space estimator (image_space.h) is tested and measured (docs/IMAGE_SPACE.md).

#include <vector>

#include "focal/image_space/image_space.h"
#include "focal/surfaces/surfaces.h"

namespace focal {

/// A geometry image: an analytic surface sampled on a regular width x height grid of its
/// parameter domain (see surfaces.h), with the exact truth per pixel alongside.
struct GeometryImage {
  GBuffer gbuffer;            ///< mask 0 (position and normal 0) outside a disc domain
  std::vector<float> k1, k2;  ///< exact principal curvatures per pixel (NaN where mask is 0)
  std::vector<float> d1, d2;  ///< 3 per pixel, exact unit principal directions (NaN where masked)
};

/// Samples `surface` at the cell centres u = u_min + (x + 1/2) (u_max - u_min) / width,
/// v = v_min + (y + 1/2) (v_max - v_min) / height (so never at a pole). Image x follows u and y
/// follows v, so the triplet (x, y), (x + 1, y), (x, y + 1) turns counter-clockwise seen from
/// outside (X_u x X_v is outward). Periodic directions are not wrapped: the last column and row
/// have no triplet. surface.target_vertices, triangulation and seed are ignored.
/// \throw InvalidInput for width or height outside [2, 16384] or invalid shape parameters.
[[nodiscard]] GeometryImage geometry_image(const SurfaceOptions& surface, int width, int height);

}  // namespace focal
