// Tests of focal::render: cameras, G-buffers of a sphere against exact geometry, pictures whose
// colours are known (constant and split fields, classes, NaN), the colour bar, and PNG files.
// OpenGL runs headless through EGL (Mesa's llvmpipe without a GPU, as in CI).
#include "focal/render/render.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>

#include "focal/image_space/image_space.h"
#include "focal/surfaces/surfaces.h"
#include "test_meshes.h"

namespace fs = std::filesystem;
using namespace focal;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr Rgb kWhite{255, 255, 255};

/// The unit sphere with its exact normals (vertex normal = position).
Mesh unit_sphere() {
  SurfaceOptions o;
  o.kind = SurfaceKind::sphere;
  o.target_vertices = 8000;
  return make_surface(o).mesh;
}

/// Largest circumradius of the faces: every point of a face inscribed in the unit sphere lies
/// at least sqrt(1 - rho^2) from the centre (its plane's distance).
double largest_circumradius(const Mesh& m) {
  double rho = 0.0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    const double ab = (b - a).norm(), bc = (c - b).norm(), ca = (a - c).norm();
    rho = std::max(rho, ab * bc * ca / (2.0 * (b - a).cross(c - a).norm()));
  }
  return rho;
}

/// Radius in pixels of the silhouette of a sphere (centre at the target) for a fitted camera:
/// perspective: tan(asin(r / d)) / tan(fov / 2) half-sides; orthographic: r / half_extent.
double silhouette_radius_pixels(const Camera& c, double r, int shorter_side) {
  if (c.projection == Projection::orthographic) return r / c.half_extent * shorter_side / 2.0;
  const double d = (c.eye - c.target).norm();
  return std::tan(std::asin(r / d)) / std::tan(c.field_of_view * kPi / 360.0) * shorter_side / 2.0;
}

bool same(const Rgb& a, const Rgb& b, int tolerance) {
  for (int c = 0; c < 3; ++c) {
    if (std::abs(int(a[c]) - int(b[c])) > tolerance) return false;
  }
  return true;
}

/// First and last x of the first run of non-background pixels in row y: the drawn object's
/// extent on that row (the legend lies further right, after a gap).
std::pair<int, int> first_run(const Image& im, int y) {
  int x = 0;
  while (x < im.width && im.pixel(x, y) == kWhite) ++x;
  const int first = x;
  while (x < im.width && im.pixel(x, y) != kWhite) ++x;
  return {first, x - 1};
}

/// A plane of 21 x 21 vertices in z = 0 (x, y in [0, 20]), seen head-on by an orthographic
/// camera: the headlight falls perpendicularly, Lambert = 1, so pixels have the map's colours
/// exactly (8-bit round trip).
FieldPictureOptions head_on_plane_options() {
  FieldPictureOptions o;
  o.width = 400;
  o.height = 300;
  o.view.projection = Projection::orthographic;
  return o;
}

/// -1 left of x = 10, +1 right of it (0 on the line).
Eigen::VectorXd split_field(const Mesh& plane) {
  Eigen::VectorXd f(plane.V.rows());
  for (Eigen::Index i = 0; i < f.size(); ++i) {
    const double x = plane.V(i, 0);
    f[i] = x < 10.0 ? -1.0 : (x > 10.0 ? 1.0 : 0.0);
  }
  return f;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Cameras

TEST(Camera, FittedCameraPutsTheCentreInTheMiddleAndTheSphereInsideTheView) {
  RowMatrixX3d V(2, 3);
  V << -1.0, 2.0, 3.0, 1.0, 4.0, 5.0;  // centre (0, 3, 4), bounding sphere radius sqrt(3)
  const Camera c = fit_camera(V, {.azimuth = 90.0, .elevation = 0.0});
  EXPECT_NEAR((c.target - Eigen::Vector3d(0, 3, 4)).norm(), 0.0, 1e-12);
  // Azimuth 90 puts the eye on +x.
  EXPECT_GT(c.eye.x(), c.target.x());
  EXPECT_NEAR(c.eye.y(), 3.0, 1e-12);
  const Eigen::Vector4d clip = view_projection_matrix(c, 1.5) * Eigen::Vector4d(0, 3, 4, 1);
  EXPECT_NEAR(clip.x() / clip.w(), 0.0, 1e-12);
  EXPECT_NEAR(clip.y() / clip.w(), 0.0, 1e-12);
  EXPECT_GT(c.near, 0.0);
  EXPECT_LT(c.near, (c.eye - c.target).norm() - std::sqrt(3.0));
  EXPECT_GT(c.far, (c.eye - c.target).norm() + std::sqrt(3.0));
}

TEST(Camera, InvalidCamerasAreRejected) {
  Camera c = look_at({1, 1, 1}, {1, 1, 1});
  EXPECT_THROW((void)view_projection_matrix(c, 1.0), InvalidInput);
  c = look_at({0, 5, 0}, {0, 0, 0}, {0, 1, 0});  // up parallel to the viewing direction
  EXPECT_THROW((void)view_projection_matrix(c, 1.0), InvalidInput);
  EXPECT_THROW((void)orbit_camera({0, 0, 0}, 0.0), InvalidInput);
  EXPECT_THROW((void)fit_camera(RowMatrixX3d::Constant(2, 3, NAN)), InvalidInput);
}

// ---------------------------------------------------------------------------------------------
// G-buffers

class SphereGBuffer : public ::testing::TestWithParam<Projection> {};

TEST_P(SphereGBuffer, PositionsNormalsAndMaskMatchTheSphere) {
  const Mesh m = unit_sphere();
  const int width = 320, height = 240;
  const Camera camera =
      fit_camera(m.V, {.azimuth = 30.0, .elevation = 20.0, .projection = GetParam()});
  const GBuffer g = rasterise_gbuffer(m.V, m.F, m.N, camera, width, height);
  ASSERT_EQ(g.width, width);
  ASSERT_EQ(g.height, height);
  ASSERT_EQ(g.position.size(), 3u * width * height);
  ASSERT_EQ(g.mask.size(), std::size_t(width) * height);

  const double facet = largest_circumradius(m);
  const double inner = std::sqrt(1.0 - facet * facet);
  const Eigen::Matrix4d vp = view_projection_matrix(camera, double(width) / height);
  // Float positions and normals: 1e-5 is about 100 float ulps at 1.
  constexpr double kFloat = 1e-5;
  const double R = silhouette_radius_pixels(camera, 1.0, std::min(width, height));
  int covered = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * width + x;
      // Pixel centres relative to the image centre, y up.
      const double dx = x + 0.5 - width / 2.0, dy = height / 2.0 - (y + 0.5);
      const double rho = std::hypot(dx, dy);
      // One pixel of slack either side of the exact silhouette circle (pixel-centre sampling).
      if (rho < R - 1.0) {
        ASSERT_EQ(g.mask[i], 1) << x << "," << y;
      }
      if (rho > R + 1.0) {
        ASSERT_EQ(g.mask[i], 0) << x << "," << y;
      }
      if (!g.mask[i]) {
        EXPECT_EQ(g.position[3 * i], 0.0f);
        continue;
      }
      ++covered;
      const Eigen::Vector3d p(g.position[3 * i], g.position[3 * i + 1], g.position[3 * i + 2]);
      const Eigen::Vector3d n(g.normal[3 * i], g.normal[3 * i + 1], g.normal[3 * i + 2]);
      ASSERT_LE(p.norm(), 1.0 + kFloat);
      ASSERT_GE(p.norm(), inner - kFloat);
      ASSERT_NEAR(n.norm(), 1.0, kFloat);
      // Vertex normals are the vertex positions, so the interpolated normal is parallel to the
      // interpolated position exactly (same barycentric weights).
      ASSERT_LT((n - p.normalized()).norm(), 2 * kFloat);
      // The near side won the depth test: the normal faces the eye, except that near the
      // silhouette a front-facing facet's interpolated normal may turn away by up to the
      // facet's angular size (about its circumradius, in radians); the far side would give
      // cosines near -1.
      const Eigen::Vector3d to_eye = camera.projection == Projection::perspective
                                         ? Eigen::Vector3d(camera.eye - p)
                                         : Eigen::Vector3d(camera.eye - camera.target);
      ASSERT_GT(n.dot(to_eye.normalized()), -facet);
      // The stored point projects back onto the pixel's centre (rows from the top).
      const Eigen::Vector4d clip = vp * p.homogeneous();
      const double px = (clip.x() / clip.w() + 1.0) * width / 2.0;
      const double py = (1.0 - clip.y() / clip.w()) * height / 2.0;
      ASSERT_NEAR(px, x + 0.5, 0.01);
      ASSERT_NEAR(py, y + 0.5, 0.01);
    }
  }
  // Area of the disc; the pixelised boundary adds or removes at most a 1-pixel ring (2 pi R).
  EXPECT_NEAR(covered, kPi * R * R, 2 * kPi * R);
}

INSTANTIATE_TEST_SUITE_P(Projections, SphereGBuffer,
                         ::testing::Values(Projection::perspective, Projection::orthographic));

TEST(GBuffer, EmptyViewHasNoCoverage) {
  const Mesh m = unit_sphere();
  Camera c = fit_camera(m.V);
  c.target += Eigen::Vector3d(100, 0, 0);  // looking away from the sphere
  c.eye += Eigen::Vector3d(100, 0, 0);
  const GBuffer g = rasterise_gbuffer(m.V, m.F, m.N, c, 64, 48);
  for (auto v : g.mask) ASSERT_EQ(v, 0);
}

TEST(GBuffer, BadArgumentsAreInvalidInput) {
  const Mesh m = unit_sphere();
  const Camera c = fit_camera(m.V);
  EXPECT_THROW((void)rasterise_gbuffer(m.V, m.F, RowMatrixX3d(0, 3), c, 64, 64), InvalidInput);
  EXPECT_THROW((void)rasterise_gbuffer(m.V, m.F, m.N, c, 0, 64), InvalidInput);
  EXPECT_THROW((void)rasterise_gbuffer(m.V, m.F, m.N, c, 64, 20000), InvalidInput);
  RowMatrixX3i F = m.F;
  F(0, 0) = static_cast<int>(m.V.rows());
  EXPECT_THROW((void)rasterise_gbuffer(m.V, F, m.N, c, 64, 64), InvalidInput);
}

// ---------------------------------------------------------------------------------------------
// Colour maps

TEST(ColourMap, DivergingIsWhiteAtZeroAndSaturatedAtTheEnds) {
  const ColourRange r{-2.0, 4.0};
  EXPECT_EQ(map_colour(ColourMap::diverging, 0.0, r), (Rgb{247, 247, 247}));
  EXPECT_EQ(map_colour(ColourMap::diverging, 4.0, r), (Rgb{178, 24, 43}));
  EXPECT_EQ(map_colour(ColourMap::diverging, 9.0, r), (Rgb{178, 24, 43}));  // clamped
  EXPECT_EQ(map_colour(ColourMap::diverging, -2.0, r), (Rgb{33, 102, 172}));
  // Each side scales separately: half of hi and half of lo are the same distance from white.
  EXPECT_EQ(map_colour(ColourMap::diverging, 2.0, r), (Rgb{244, 165, 130}));
  EXPECT_EQ(map_colour(ColourMap::diverging, -1.0, r), (Rgb{146, 197, 222}));
  EXPECT_EQ(map_colour(ColourMap::diverging, NAN, r), grey_for_missing());
}

TEST(ColourMap, ClassesHaveDistinctColoursAndUndefinedIsGrey) {
  for (int a = 0; a < 5; ++a) {
    EXPECT_NE(map_colour(ColourMap::classes, a, {}), grey_for_missing());
    for (int b = a + 1; b < 5; ++b) {
      EXPECT_NE(map_colour(ColourMap::classes, a, {}), map_colour(ColourMap::classes, b, {}));
    }
  }
  EXPECT_EQ(map_colour(ColourMap::classes, 5.0, {}), grey_for_missing());
  EXPECT_EQ(map_colour(ColourMap::classes, 7.0, {}), grey_for_missing());
}

TEST(ColourMap, RobustRangeIgnoresTheLargestValuesAndNaN) {
  Eigen::VectorXd v(102);
  for (int i = 0; i < 100; ++i) v[i] = (i % 2 ? 1.0 : -1.0) * (i + 1) / 100.0;  // |v| 0.01 .. 1
  v[100] = 1e6;
  v[101] = NAN;
  // 101 finite magnitudes; nearest rank ceil(0.95 * 101) = 96 is 0.96.
  const ColourRange r = robust_symmetric_range(v, 95.0);
  EXPECT_DOUBLE_EQ(r.hi, 0.96);
  EXPECT_DOUBLE_EQ(r.lo, -0.96);
  EXPECT_DOUBLE_EQ(robust_symmetric_range(Eigen::VectorXd::Zero(4)).hi, 1.0);
  EXPECT_THROW((void)robust_symmetric_range(v, 0.0), InvalidInput);
}

// ---------------------------------------------------------------------------------------------
// Pictures

TEST(Picture, SphereWithConstantFieldHasTheMapColourTimesTheShading) {
  const Mesh m = unit_sphere();
  FieldPictureOptions o;
  o.width = 400;
  o.height = 300;
  o.range = ColourRange{-2.0, 2.0};
  const Image im =
      render_field_picture(m.V, m.F, m.N, Eigen::VectorXd::Constant(m.V.rows(), 1.0), o);
  ASSERT_EQ(im.width, 400);
  ASSERT_EQ(im.height, 300);
  const Rgb expected = map_colour(ColourMap::diverging, 1.0, *o.range);
  const auto [left, right] = first_run(im, o.height / 2);
  ASSERT_LT(left, right);
  int checked = 0;
  double brightest = 0.0;
  for (int y = 2; y + 2 < im.height; ++y) {
    for (int x = left; x <= right; ++x) {
      // Interior pixels only: multisampled edges blend with the background.
      bool interior = true;
      for (int dy = -2; dy <= 2 && interior; ++dy) {
        for (int dx = -2; dx <= 2 && interior; ++dx) interior = im.pixel(x + dx, y + dy) != kWhite;
      }
      if (!interior) continue;
      const Rgb p = im.pixel(x, y);
      // Lambert shading scales all channels alike: p = s * expected, s in [ambient 0.35, 1].
      const double s = p[0] / double(expected[0]);
      ASSERT_GE(s, 0.35 - 0.01);
      ASSERT_LE(s, 1.0 + 0.01);
      // 8-bit rounding of the shaded colour (0.5) and of s through p[0] (0.5 * 247/244): 1.5.
      for (int c = 1; c < 3; ++c) ASSERT_NEAR(p[c], s * expected[c], 1.5) << x << "," << y;
      brightest = std::max(brightest, s);
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
  // The point facing the eye is fully lit (the headlight is at the eye).
  EXPECT_GT(brightest, 0.98);
  // Background in the corners.
  EXPECT_EQ(im.pixel(0, 0), kWhite);
  EXPECT_EQ(im.pixel(0, im.height - 1), kWhite);
}

TEST(Picture, ColourBarShowsBothEndsOfTheMapAndLabels) {
  const Mesh m = unit_sphere();
  FieldPictureOptions o;
  o.width = 400;
  o.height = 300;
  o.range = ColourRange{-2.0, 2.0};
  const Image im = render_field_picture(m.V, m.F, m.N, Eigen::VectorXd::Zero(m.V.rows()), o);
  const auto [left, right] = first_run(im, o.height / 2);
  int red = 0, blue = 0, ink = 0;
  for (int y = 0; y < im.height; ++y) {
    for (int x = right + 1; x < im.width; ++x) {
      const Rgb p = im.pixel(x, y);
      red += same(p, {178, 24, 43}, 1);
      blue += same(p, {33, 102, 172}, 1);
      ink += p == Rgb{0, 0, 0};
    }
  }
  EXPECT_GT(red, 0);
  EXPECT_GT(blue, 0);
  EXPECT_GT(ink, 50);  // outline, ticks and the tick labels
}

TEST(Picture, PlaneSplitIntoPositiveAndNegativeIsRedAndBlue) {
  const Mesh plane = test::flat_grid(21);
  const FieldPictureOptions o = head_on_plane_options();
  FieldPictureOptions ranged = o;
  ranged.range = ColourRange{-1.0, 1.0};
  const Image im = render_field_picture(plane.V, plane.F, plane.N, split_field(plane), ranged);
  const auto [left, right] = first_run(im, o.height / 2);
  const double pixels_per_unit = (right - left + 1) / 20.0;
  for (int y = o.height / 2 - 20; y <= o.height / 2 + 20; ++y) {
    for (int x = left + 2; x <= right - 2; ++x) {
      const double world_x = (x + 0.5 - left) / pixels_per_unit;
      // Faces touching x = 10 blend the two colours; one unit either side is pure.
      if (world_x < 8.9) {
        ASSERT_TRUE(same(im.pixel(x, y), {33, 102, 172}, 1)) << x << "," << y;
      }
      if (world_x > 11.1) {
        ASSERT_TRUE(same(im.pixel(x, y), {178, 24, 43}, 1)) << x << "," << y;
      }
    }
  }
}

TEST(Picture, ClassesAndMissingValuesHaveTheirColours) {
  const Mesh plane = test::flat_grid(21);
  FieldPictureOptions o = head_on_plane_options();
  o.colour_map = ColourMap::classes;
  Eigen::VectorXd classes(plane.V.rows());
  for (Eigen::Index i = 0; i < classes.size(); ++i) {
    classes[i] =
        static_cast<double>(plane.V(i, 0) <= 10.0 ? PointClass::elliptic : PointClass::hyperbolic);
  }
  Image im = render_field_picture(plane.V, plane.F, plane.N, classes, o);
  const int y = o.height / 2;
  auto [left, right] = first_run(im, y);
  EXPECT_TRUE(same(im.pixel(left + 5, y), map_colour(ColourMap::classes, 0, {}), 1));
  EXPECT_TRUE(same(im.pixel(right - 5, y), map_colour(ColourMap::classes, 1, {}), 1));

  o.colour_map = ColourMap::diverging;
  im = render_field_picture(plane.V, plane.F, plane.N,
                            Eigen::VectorXd::Constant(plane.V.rows(), NAN), o);
  std::tie(left, right) = first_run(im, y);
  EXPECT_TRUE(same(im.pixel((left + right) / 2, y), grey_for_missing(), 1));
}

TEST(Picture, DirectionGlyphsAndTitleAddDarkPixels) {
  const Mesh plane = test::flat_grid(21);
  const FieldPictureOptions plain = head_on_plane_options();
  const auto dark_pixels_left_of_legend = [](const Image& im) {
    const int end = first_run(im, im.height / 2).second;
    int n = 0;
    for (int y = 0; y < im.height; ++y) {
      for (int x = 0; x <= end; ++x) {
        const Rgb p = im.pixel(x, y);
        n += p[0] < 60 && p[1] < 60 && p[2] < 60;
      }
    }
    return n;
  };
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(plane.V.rows());
  EXPECT_EQ(
      dark_pixels_left_of_legend(render_field_picture(plane.V, plane.F, plane.N, zero, plain)), 0);
  FieldPictureOptions glyphs = plain;
  glyphs.directions = RowMatrixX3d::Zero(plane.V.rows(), 3);
  glyphs.directions.col(0).setOnes();
  EXPECT_GT(
      dark_pixels_left_of_legend(render_field_picture(plane.V, plane.F, plane.N, zero, glyphs)),
      100);
  FieldPictureOptions titled = plain;
  titled.title = "H, mean curvature";
  const Image t = render_field_picture(plane.V, plane.F, plane.N, zero, titled);
  int ink = 0;
  for (int x = 0; x < t.width; ++x) {
    for (int y = 0; y < 10; ++y) ink += t.pixel(x, y) == Rgb{0, 0, 0};
  }
  EXPECT_GT(ink, 50);
}

TEST(Picture, FocalMeshPanelsKeepThePictureSize) {
  const Mesh m = unit_sphere();
  FieldPictureOptions o;
  o.width = 600;
  o.height = 200;
  CurvatureResult c;
  c.k1 = c.k2 = c.H = c.K = Eigen::VectorXd::Ones(m.V.rows());
  c.d1 = c.d2 = RowMatrixX3d::Zero(m.V.rows(), 3);
  c.residual = Eigen::VectorXd::Zero(m.V.rows());
  c.point_class = VectorXu8::Constant(m.V.rows(), 3);
  o.focal_meshes = focal_meshes(m.V, m.F, m.N, c);
  const Image im = render_field_picture(m.V, m.F, m.N, c.H, o);
  EXPECT_EQ(im.width, 600);
  EXPECT_EQ(im.height, 200);
}

TEST(Picture, BadArgumentsAreInvalidInput) {
  const Mesh plane = test::flat_grid(5);
  const Eigen::VectorXd f = Eigen::VectorXd::Zero(plane.V.rows());
  FieldPictureOptions o;
  EXPECT_THROW((void)render_field_picture(plane.V, plane.F, plane.N, Eigen::VectorXd::Zero(3), o),
               InvalidInput);
  o.width = 10;
  EXPECT_THROW((void)render_field_picture(plane.V, plane.F, plane.N, f, o), InvalidInput);
  o = {};
  o.range = ColourRange{1.0, 1.0};
  EXPECT_THROW((void)render_field_picture(plane.V, plane.F, plane.N, f, o), InvalidInput);
  o = {};
  o.directions = RowMatrixX3d::Zero(2, 3);
  EXPECT_THROW((void)render_field_picture(plane.V, plane.F, plane.N, f, o), InvalidInput);
}

// ---------------------------------------------------------------------------------------------
// Point clouds: splats

namespace {

/// n points on the unit sphere (Fibonacci spiral: near-uniform spacing); normals = positions.
RowMatrixX3d fibonacci_sphere(int n) {
  RowMatrixX3d V(n, 3);
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double r = std::sqrt(1.0 - z * z);
    V.row(i) << r * std::cos(golden * i), z, r * std::sin(golden * i);
  }
  return V;
}

}  // namespace

// The cloud, seen head-on by an orthographic camera, covers the disc the sphere projects to and
// nothing outside it: no gaps between splats, none reaching out (oriented discs tangent to the
// sphere stay within 1 + r^2/2 of the centre). Without normals the discs face the eye and may
// reach out by their radius (0.7 x 1.18 x spacing = 3 pixels here): margin 5.
TEST(Picture, CloudSplatsCoverTheSphereAndNothingElse) {
  const RowMatrixX3d V = fibonacci_sphere(20000);
  const RowMatrixX3i no_faces(0, 3);
  FieldPictureOptions o;
  o.width = 400;
  o.height = 300;
  o.view.projection = Projection::orthographic;
  o.range = ColourRange{-2.0, 2.0};
  const Eigen::VectorXd field = Eigen::VectorXd::Constant(V.rows(), 1.0);
  const double R = silhouette_radius_pixels(fit_camera(V, o.view), 1.0, o.height);
  const Rgb expected = map_colour(ColourMap::diverging, 1.0, *o.range);
  for (const bool with_normals : {true, false}) {
    SCOPED_TRACE(with_normals ? "normals" : "no normals");
    const RowMatrixX3d N =
        with_normals
            ? V
            : RowMatrixX3d::Constant(V.rows(), 3, std::numeric_limits<double>::quiet_NaN());
    const Image im = render_field_picture(V, no_faces, N, field, o);
    const auto [left, right] = first_run(im, o.height / 2);
    ASSERT_LT(left, right);
    EXPECT_NEAR(right - left + 1, 2.0 * R, with_normals ? 3.0 : 10.0);
    const double cx = (left + right + 1) / 2.0, cy = o.height / 2.0;
    const double outer = with_normals ? 2.0 : 5.0;
    int inside = 0, holes = 0, stray = 0;
    for (int y = 0; y < o.height; ++y) {
      for (int x = 0; x < right + 20; ++x) {
        const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
        const bool covered = im.pixel(x, y) != kWhite;
        if (d < R - 2.0) {
          ++inside;
          holes += covered ? 0 : 1;
        } else if (d > R + outer) {
          stray += covered ? 1 : 0;
        }
      }
    }
    EXPECT_GT(inside, 50000);
    EXPECT_EQ(holes, 0);
    EXPECT_EQ(stray, 0);
    // The point facing the eye is fully lit and has the map's colour.
    const Rgb centre = im.pixel(static_cast<int>(cx), static_cast<int>(cy));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(centre[c], expected[c], 3.0);
  }
}

// Splats are depth-tested: a plane of red points in front of a plane of blue points hides it.
TEST(Picture, CloudSplatsAreDepthTested) {
  const int n = 60;
  RowMatrixX3d V(2 * n * n, 3);
  Eigen::VectorXd field(V.rows());
  for (int layer = 0; layer < 2; ++layer) {
    for (int i = 0; i < n * n; ++i) {
      const int row = layer * n * n + i;
      // The far (blue) layer first in the arrays, so that drawing order alone would show it.
      V.row(row) << (i % n) / double(n - 1), (i / n) / double(n - 1), layer == 0 ? -0.5 : 0.0;
      field[row] = layer == 0 ? -1.0 : 1.0;
    }
  }
  const RowMatrixX3d N =
      RowMatrixX3d::Constant(V.rows(), 3, 0.0).rowwise() + Eigen::RowVector3d(0.0, 0.0, 1.0);
  FieldPictureOptions o = head_on_plane_options();
  o.range = ColourRange{-1.0, 1.0};
  const Image im = render_field_picture(V, RowMatrixX3i(0, 3), N, field, o);
  const auto [left, right] = first_run(im, o.height / 2);
  ASSERT_LT(left, right);
  const Rgb red = map_colour(ColourMap::diverging, 1.0, *o.range);
  EXPECT_EQ(im.pixel((left + right) / 2, o.height / 2), red);
}

TEST(Picture, CloudFocalPointsGlyphsAndBadSplatRadius) {
  const RowMatrixX3d V = fibonacci_sphere(2000);
  const RowMatrixX3i no_faces(0, 3);
  CurvatureResult c;
  c.k1 = c.k2 = c.H = c.K = Eigen::VectorXd::Ones(V.rows());
  c.d1 = c.d2 = RowMatrixX3d::Zero(V.rows(), 3);
  c.d1.col(1).setOnes();
  c.residual = Eigen::VectorXd::Zero(V.rows());
  c.point_class = VectorXu8::Constant(V.rows(), 3);
  FieldPictureOptions o;
  o.width = 600;
  o.height = 200;
  o.directions = c.d1;
  o.focal_meshes = focal_meshes(V, no_faces, V, c);
  const Image im = render_field_picture(V, no_faces, V, c.H, o);
  EXPECT_EQ(im.width, 600);
  EXPECT_EQ(im.height, 200);
  o = {};
  o.splat_radius = -1.0;
  EXPECT_THROW((void)render_field_picture(V, no_faces, V, c.H, o), InvalidInput);
  o.splat_radius = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)render_field_picture(V, no_faces, V, c.H, o), InvalidInput);
  o.splat_radius = 0.05;
  EXPECT_THROW((void)render_field_picture(V, no_faces, V.topRows(5), c.H, o), InvalidInput);
  const Image fixed = render_field_picture(V, no_faces, V, c.H, o);
  EXPECT_EQ(fixed.width, o.width);
}

// ---------------------------------------------------------------------------------------------
// PNG

class Png : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    dir_ = fs::temp_directory_path() / ("focal_render_png_" + std::to_string(rd()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

TEST_F(Png, RoundTripIsExact) {
  Image im{37, 23, std::vector<std::uint8_t>(37 * 23 * 3)};
  std::mt19937 random(7);
  for (auto& b : im.rgb) b = static_cast<std::uint8_t>(random());
  write_png(dir_ / "a.png", im);
  const Image back = read_png(dir_ / "a.png");
  EXPECT_EQ(back.width, 37);
  EXPECT_EQ(back.height, 23);
  EXPECT_EQ(back.rgb, im.rgb);
  // Only the finished file is left: the temporary was renamed.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(Png, RenderedPictureRoundTrips) {
  const Mesh plane = test::flat_grid(5);
  FieldPictureOptions o;
  o.width = 128;
  o.height = 96;
  const Image im = render_field_picture(plane.V, plane.F, plane.N, split_field(plane), o);
  write_png(dir_ / "p.png", im);
  EXPECT_EQ(read_png(dir_ / "p.png").rgb, im.rgb);
}

TEST_F(Png, FailuresNameTheFileAndLeaveNothing) {
  const Image im{2, 2, std::vector<std::uint8_t>(12, 9)};
  EXPECT_THROW(write_png(dir_ / "missing" / "a.png", im), IoError);
  EXPECT_THROW(write_png(dir_ / "b.png", Image{2, 2, std::vector<std::uint8_t>(5)}), InvalidInput);
  EXPECT_TRUE(fs::is_empty(dir_));
  std::ofstream(dir_ / "not.png") << "not a png";
  try {
    (void)read_png(dir_ / "not.png");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("not.png"), std::string::npos);
  }
  EXPECT_THROW((void)read_png(dir_ / "none.png"), IoError);
}

// ---------------------------------------------------------------------------------------------
// Without any EGL driver (GLVND pointed at a vendor file that does not exist) every call throws
// RenderError naming the platforms tried. Runs in a fresh process: the display is chosen once
// per process.

TEST(RenderErrors, NoEglDriverIsRenderError) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/focal-test-vendor.json", 1);
        const Mesh plane = test::flat_grid(3);
        try {
          (void)rasterise_gbuffer(plane.V, plane.F, plane.N, fit_camera(plane.V), 8, 8);
        } catch (const RenderError& e) {
          std::fprintf(stderr, "%s\n", e.what());
          std::exit(7);
        }
        std::exit(0);
      },
      ::testing::ExitedWithCode(7), "no headless OpenGL 3.3 context: tried");
}

// ---------------------------------------------------------------------------------------------
// The image-space estimator (paper 5.1) on a rasterised G-buffer

// The sphere's vertex normals are its vertex positions over r, and the rasteriser interpolates
// both with the same barycentric weights, so every pixel's normal ray passes through the centre:
// both focal depths equal the pixel's distance |p| from it, which lies between r sqrt(1 - rho^2)
// (rho the largest facet circumradius) and r. So k1 = k2 = 1 / |p| up to float rounding.
TEST(ImageSpaceOnGBuffer, SphereGivesOneOverRadiusAwayFromTheSilhouette) {
  constexpr double r = 2.0;
  SurfaceOptions o;
  o.kind = SurfaceKind::sphere;
  o.a = r;
  o.target_vertices = 8000;
  const Mesh m = make_surface(o).mesh;
  const int side = 256;
  const Camera camera = fit_camera(m.V, {.azimuth = 30.0, .elevation = 20.0});
  const GBuffer g = rasterise_gbuffer(m.V, m.F, m.N, camera, side, side);
  const ImageCurvature c = estimate_image_curvature(g);

  const double facet = largest_circumradius(m);  // in units of r: the mesh has radius r
  const double h_low = 1.0 / r, h_high = 1.0 / (r * std::sqrt(1.0 - facet * facet / (r * r)));
  // Float: positions and normals to ~1e-7 relative, normal differences between neighbouring
  // pixels ~ footprint / r ~ 1e-2, so ~1e-5 relative in k; 1e-4 leaves a margin of ten.
  constexpr double kFloat = 1e-4;
  const double R = silhouette_radius_pixels(camera, r, side);
  int inside = 0, valid = 0;
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      const double rho = std::hypot(x + 0.5 - side / 2.0, side / 2.0 - (y + 0.5));
      if (rho > 0.9 * R) continue;  // away from the silhouette
      ++inside;
      const std::size_t i = std::size_t(y) * side + x;
      if (!c.valid[i]) continue;
      ++valid;
      ASSERT_GE(c.H[i], h_low * (1.0 - kFloat)) << x << "," << y;
      ASSERT_LE(c.H[i], h_high * (1.0 + kFloat)) << x << "," << y;
      ASSERT_NEAR(c.k1[i], c.k2[i], 2 * kFloat * h_high) << x << "," << y;
      ASSERT_NEAR(c.K[i], c.H[i] * c.H[i], 4 * kFloat * h_high * h_high) << x << "," << y;
    }
  }
  // Inside 0.9 R every triplet is covered and smooth: all pixels must be valid.
  EXPECT_EQ(valid, inside);
  EXPECT_GT(inside, 0.8 * kPi * 0.81 * R * R);
}
