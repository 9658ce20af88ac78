#pragma once
/// \file image_space.h
/// The paper's image-space estimator (Yu et al., SGP 2007, section 5.1): positions and normals
/// rasterised into float images (a G-buffer); every pixel solves the normal-ray characteristic
/// equation (eqs. 5-9) of its pixel triplet (x, y), (x + 1, y), (x, y + 1), in the frame of the
/// triplet's unit mean normal, exactly as triangle_curvature does for a mesh face (see
/// docs/IMAGE_SPACE.md for the method, the invalid-pixel rules and measured accuracy).
///
/// Conventions as everywhere in focal: outward normals, curvature positive where the surface
/// bends away from the normal (a sphere of radius r: k1 = k2 = +1/r), d1 belongs to k1 and
/// (d1, d2, N) is right-handed with N the triplet's mean normal. The triplet's orientation (which
/// way the image's y axis points) does not matter; the normals' direction does.
///
/// All arithmetic is float32, the G-buffer's precision and the GPU's; positions are taken
/// relative to each triplet's centroid and size first, so results do not depend on the units or
/// on where the surface lies. docs/IMAGE_SPACE.md states the measured accuracy.

#include <cstdint>
#include <vector>

#include "focal/cuda/image_state.h"

namespace focal {

/// Float images of one view, row-major, pixel (x, y) at index y * width + x.
struct GBuffer {
  int width = 0;
  int height = 0;
  std::vector<float> position;  ///< 3 per pixel (x, y, z), world coordinates, any units
  /// 3 per pixel, outward normal. Need not be unit length (rasterisers interpolate normals);
  /// a zero or non-finite normal in a covered pixel invalidates the triplets that use it.
  std::vector<float> normal;
  std::vector<std::uint8_t> mask;  ///< non-zero where a surface covers the pixel
};

struct ImageSpaceOptions {
  /// Depth discontinuities: a triplet whose edge along image x (or y) is longer than this many
  /// times the local pixel footprint along x (or y) is invalid. The footprint is the median
  /// length of the 15 parallel pixel edges around the triplet's edge (3 along it, 5 across), so
  /// it follows perspective and anisotropic pixels, and the few edges a discontinuity crosses do
  /// not move it. Must be > 1 (infinity disables the test); the default 4 passes smooth surfaces
  /// (a footprint changes by O(h) from pixel to pixel) and catches any jump of 4 footprints.
  double discontinuity_ratio = 4.0;
  /// Triplet averaging against noise: the symmetrised shape operators M = G X^-1 of the valid
  /// triplets in the (2 w + 1)^2 window around a pixel, each rotated into the pixel's frame, are
  /// averaged (weighted by the triplets' relative area), and k1, k2, d1, d2 are the eigen-pairs
  /// of the mean. 0 = none: the pixel's own characteristic equation. In [0, 16].
  int window = 0;
};

/// Per-pixel fields, width * height each (3 per pixel for d1, d2), in the units of the
/// G-buffer's positions. Invalid pixels (valid = 0) have NaN in every float field: pixels not
/// covered, whose triplet leaves the mask or the image (the last column and row), crosses a depth
/// discontinuity, has a normal outside the hemisphere of the triplet's mean normal, or has no
/// area in the ray frame.
struct ImageCurvature {
  int width = 0;
  int height = 0;
  std::vector<float> k1, k2, H, K;  ///< k1 >= k2, H = (k1 + k2) / 2, K = k1 k2
  std::vector<float> focal_depth1,
      focal_depth2;                 ///< -1/k1, -1/k2 along the normal (+-inf at k = 0)
  std::vector<float> d1, d2;        ///< 3 per pixel, unit principal directions
  std::vector<std::uint8_t> valid;  ///< 1 where the fields hold an estimate
};

/// CPU reference, parallel over pixels; the same result for any thread count.
/// \throw InvalidInput when width or height is negative, the arrays' sizes disagree with them
///        (position and normal: 3 width height; mask: width height), or an option is out of range.
[[nodiscard]] ImageCurvature estimate_image_curvature(const GBuffer& gbuffer,
                                                      const ImageSpaceOptions& options = {});

/// The same on CUDA device `device`, one thread per pixel, the same per-pixel function. Agrees with
/// the CPU reference up to float rounding (fused multiply-adds on the device). \throw DeviceError
/// without the CUDA backend or the device, or on a CUDA error;
///        InvalidInput as estimate_image_curvature.
[[nodiscard]] ImageCurvature estimate_image_curvature_cuda(const GBuffer& gbuffer,
                                                           const ImageSpaceOptions& options = {},
                                                           int device = 0);

/// Image space on CUDA device `device` for a stream of frames of one size (an interactive
/// viewer, a video): the device buffers of the G-buffer, of the fields and of the window's
/// operators, a stream and page-locked (pinned) host buffers for the transfers are allocated
/// once, by the constructor, and kept until the context is destroyed. The one-shot
/// estimate_image_curvature_cuda allocates and frees them on every call.
///
/// Each frame gives the bits estimate_image_curvature_cuda(gbuffer, options, device) gives: the
/// same kernels on the same data. The stages can be called on their own (upload, compute,
/// download), e.g. to time the kernels alone or to compute several times on one upload.
/// Calls are synchronous and leave the calling thread's current CUDA device as it was. A context
/// is not thread-safe: one per thread.
class ImageCurvatureCudaContext {
 public:
  /// \throw DeviceError without the CUDA backend or the device, or when the buffers cannot be
  ///        allocated; InvalidInput when width or height is below 1 or the options are out of
  ///        range (as estimate_image_curvature).
  ImageCurvatureCudaContext(int width, int height, const ImageSpaceOptions& options = {},
                            int device = 0);

  /// One frame: upload, compute, download.
  /// \throw InvalidInput when the G-buffer's size is not the context's or its arrays disagree
  ///        with it; DeviceError on a CUDA error.
  [[nodiscard]] ImageCurvature estimate(const GBuffer& gbuffer);
  /// The same into `out`, whose arrays are reused when already of the context's size.
  void estimate(const GBuffer& gbuffer, ImageCurvature& out);

  /// Copies the G-buffer to the device (through the pinned buffers). \throw as estimate.
  void upload(const GBuffer& gbuffer);
  /// Runs the kernels on the last uploaded G-buffer and waits for them.
  /// \throw InvalidInput before any upload; DeviceError on a CUDA error.
  void compute();
  /// The fields of the last compute into `out` (resized to the context's size if needed).
  /// \throw InvalidInput before any compute; DeviceError on a CUDA error.
  void download(ImageCurvature& out);

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  [[nodiscard]] int device() const { return device_; }

 private:
  int width_, height_, device_;
  ImageSpaceOptions options_;
  bool uploaded_ = false, computed_ = false;
  detail::ImageDeviceStatePtr state_;
};

}  // namespace focal
