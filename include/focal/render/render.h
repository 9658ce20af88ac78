#pragma once
/// \file render.h
/// Rasterisation through OpenGL on a headless EGL context (library focal::render, separate from
/// the core library so that focal::focal needs no OpenGL): G-buffers of positions and normals
/// for the image-space estimator (paper section 5.1, image_space.h), and pictures of per-vertex
/// fields with a colour bar, written as PNG. See docs/RENDER.md.
///
/// Every call creates its own OpenGL 3.3 core context on the calling thread and releases it
/// before returning; the EGL display is chosen once per process (EGL_EXT_platform_device, then
/// EGL_MESA_platform_surfaceless, then the default display). It runs on Mesa (llvmpipe, no GPU
/// needed) and on the NVIDIA driver.
///
/// Images are row-major with row 0 at the top: pixel (x, y) is at index y * width + x.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "focal/core/mesh.h"
#include "focal/curvature/focal_mesh.h"
#include "focal/image_space/image_space.h"

namespace focal {

/// No OpenGL context could be had (no EGL display, no OpenGL 3.3 core context, a framebuffer
/// the driver rejects, a shader that does not compile). The message says what was tried.
class RenderError : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

enum class Projection { perspective, orthographic };

/// A pinhole (or orthographic) camera in world coordinates.
struct Camera {
  Eigen::Vector3d eye{0.0, 0.0, 3.0};
  Eigen::Vector3d target{0.0, 0.0, 0.0};
  Eigen::Vector3d up{0.0, 1.0, 0.0};  ///< need not be orthogonal to the viewing direction
  Projection projection = Projection::perspective;
  /// Perspective: the full opening angle across the shorter side of the image, in degrees
  /// (so that a fitted object fits whatever the aspect ratio).
  double field_of_view = 30.0;
  /// Orthographic: half the extent of the view across the shorter side, in world units.
  double half_extent = 1.0;
  double near = 0.1;   ///< distance of the near clipping plane from the eye, > 0
  double far = 100.0;  ///< distance of the far clipping plane, > near
};

/// A direction to look from, for cameras fitted to an object.
struct OrbitView {
  /// Degrees about the +y axis; 0 puts the eye on the +z side looking towards -z, 90 on +x.
  double azimuth = 0.0;
  /// Degrees above the xz plane (90 looks straight down); kept within [-89.9, 89.9].
  double elevation = 0.0;
  Projection projection = Projection::perspective;
  double field_of_view = 30.0;  ///< perspective opening angle across the shorter side, degrees
  /// The sphere fitted into the view is this much larger than the object's bounding sphere,
  /// leaving a margin around the silhouette.
  double margin = 1.05;
};

/// A camera at `eye` looking at `target`, other fields at their defaults.
[[nodiscard]] Camera look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                             const Eigen::Vector3d& up = Eigen::Vector3d::UnitY());

/// A camera on `view`'s direction around `centre` whose view holds the sphere of `radius`
/// (times view.margin) across the shorter side of the image; near and far enclose the sphere.
/// \throw InvalidInput when radius is not finite and positive or the view's numbers are invalid.
[[nodiscard]] Camera orbit_camera(const Eigen::Vector3d& centre, double radius,
                                  const OrbitView& view = {});

/// orbit_camera around the bounding sphere of the finite rows of V (centre of the bounding box,
/// radius the largest distance from it). \throw InvalidInput when V has no finite row.
[[nodiscard]] Camera fit_camera(PositionsRef V, const OrbitView& view = {});

/// 4 x 4 world-to-clip matrix (OpenGL conventions, clip z in [-w, w]) for an image of the
/// given aspect ratio (width / height). \throw InvalidInput for an invalid camera.
[[nodiscard]] Eigen::Matrix4d view_projection_matrix(const Camera& camera, double aspect);

/// Rasterises the mesh into a G-buffer of width x height pixels: per covered pixel the world
/// position and the unit normal interpolated from N (perspective-correct) at the pixel centre;
/// position and normal are 0 and mask 0 where no triangle covers the pixel. No multisampling.
/// Faces with a non-finite position or normal at a corner are not drawn.
/// \param V #V x 3 positions. \param F #F x 3 triangles. \param N #V x 3 vertex normals (required).
/// \throw InvalidInput for wrong shapes, N without #V rows, sizes outside [1, 16384].
/// \throw RenderError when no OpenGL context or framebuffer can be had.
[[nodiscard]] GBuffer rasterise_gbuffer(PositionsRef V, FacesRef F, NormalsRef N,
                                        const Camera& camera, int width, int height);

/// An 8-bit RGB image, 3 bytes per pixel, row 0 at the top.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  [[nodiscard]] std::array<std::uint8_t, 3> pixel(int x, int y) const {
    const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

using Rgb = std::array<std::uint8_t, 3>;

enum class ColourMap {
  /// Blue - white - red (ColorBrewer RdBu), white at 0: for signed fields (H, K, k1, k2).
  diverging,
  /// One colour per PointClass code (curvature.h), a legend instead of a colour bar.
  classes,
};

/// The value range of a diverging map: lo maps to the blue end, hi to the red end. When
/// lo < 0 < hi, 0 is white and each side is scaled separately (v / hi on the red side, v / lo on
/// the blue side); otherwise the whole map spans [lo, hi] linearly. Values outside are clamped.
struct ColourRange {
  double lo = -1.0;
  double hi = 1.0;
};

/// The colour of `value` on a map; NaN (and, for `classes`, codes outside 0-5 and `undefined`)
/// give grey_for_missing(). Ignores `range` for `classes`.
[[nodiscard]] Rgb map_colour(ColourMap map, double value, const ColourRange& range);
/// The grey of values that do not exist (NaN, undefined class).
[[nodiscard]] Rgb grey_for_missing();

/// The symmetric range [-p, p], p the given percentile (in (0, 100]) of |value| over the finite
/// values, so that a few extreme vertices do not wash out the map. p = 1 when no value is finite
/// or all are 0. \throw InvalidInput for a percentile outside (0, 100].
[[nodiscard]] ColourRange robust_symmetric_range(const Eigen::Ref<const Eigen::VectorXd>& values,
                                                 double percentile = 98.0);

struct FieldPictureOptions {
  int width = 1200;  ///< of the whole picture (panels, title and colour bar), in [64, 16384]
  int height = 900;  ///< in [64, 16384]
  OrbitView view;    ///< the camera is fitted to the base mesh's bounding sphere from here
  std::optional<Camera> camera;  ///< a camera of your own instead of the fitted one
  ColourMap colour_map = ColourMap::diverging;
  /// The diverging map's range; none = robust_symmetric_range(field, range_percentile).
  std::optional<ColourRange> range;
  double range_percentile = 95.0;
  std::string title;  ///< drawn above the panels (ASCII; other bytes show as '?')
  /// Principal-direction glyphs: #V x 3 unit directions (d1 or d2), drawn as short dark
  /// segments through a subsample of about `glyph_count` vertices; 0 rows for none. Rows with
  /// a non-finite entry are skipped.
  RowMatrixX3d directions;
  int glyph_count = 2500;
  /// Point clouds (F with 0 rows) are drawn as splats: a disc per point in the plane normal to
  /// its normal (facing the eye where the normal is not finite), depth-tested and shaded as
  /// faces are. Radius in world units; 0 = 0.7 x the mean distance of each point to its 8
  /// nearest (no gaps on Poisson-disk samples; docs/POINTS.md).
  double splat_radius = 0.0;
  /// When set, two more panels right of the base mesh show Gamma_1 and Gamma_2 coloured by the
  /// same field (same vertex order as the base mesh), from the same camera, with flat shading.
  std::optional<FocalMeshes> focal_meshes;
  /// Multisampling (samples per pixel, clamped to what the driver offers; 1 or less for none).
  int samples = 4;
};

/// A picture of a per-vertex scalar field on a mesh: Lambert shading under a headlight (ambient
/// 0.35), coloured per vertex by the map, background white, the title at the top and the colour
/// bar (or class legend) on the right.
/// \param field #V values (H, K, k1, k2, or PointClass codes with ColourMap::classes).
/// \throw InvalidInput for wrong shapes or options out of range. \throw RenderError as above.
[[nodiscard]] Image render_field_picture(PositionsRef V, FacesRef F, NormalsRef N,
                                         const Eigen::Ref<const Eigen::VectorXd>& field,
                                         const FieldPictureOptions& options = {});

/// Writes an 8-bit RGB PNG (libpng) to a temporary file beside `path`, then renames it: a failed
/// write leaves `path` as it was. \throw IoError naming the file. \throw InvalidInput for an
/// image whose pixel count does not match its size.
void write_png(const std::filesystem::path& path, const Image& image);

/// Reads a PNG into 8-bit RGB (palette, grey and 16-bit images are converted, alpha dropped).
/// \throw IoError naming the file when it is missing or not a readable PNG.
[[nodiscard]] Image read_png(const std::filesystem::path& path);

}  // namespace focal
