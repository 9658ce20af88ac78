// Pictures of a per-vertex field: the mesh (and optionally its focal meshes) rendered with
// OpenGL, multisampled, into RGBA8; then the title, panel labels and the colour bar or class
// legend drawn on the CPU with the bitmap font.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "core/memory.h"
#include "focal/core/execution.h"
#include "focal/curvature/curvature.h"
#include "focal/points/neighbours.h"
#include "focal/render/render.h"
#include "render/bitmap_font.h"
#include "render/gl_context.h"
#include "render/gl_mesh.h"

namespace focal {
namespace {

using render_detail::draw_text;
using render_detail::kGlyphHeight;
using render_detail::require_no_gl_error;
using render_detail::text_width;

constexpr int kMinSize = 64;
constexpr int kMaxSize = 16384;
// Share of the light that reaches surfaces seen edge-on, so that no part of the mesh goes black.
constexpr float kAmbient = 0.35f;
constexpr Rgb kBackground{255, 255, 255};
constexpr Rgb kInk{0, 0, 0};
constexpr float kGlyphGrey = 0.08f;

/// A rectangle of the picture in pixels, (x, y) its top-left corner, y downwards.
struct Rect {
  int x = 0, y = 0, width = 0, height = 0;
};

struct Layout {
  int scale = 1;  ///< of the bitmap font
  Rect title;
  std::vector<Rect> panels;  ///< the 3D views
  std::vector<Rect> labels;  ///< a label band above each panel (height 0 with one panel)
  Rect legend;
};

/// What one panel shows: a mesh on the GPU-ready arrays, and optional line glyphs.
struct PanelContent {
  render_detail::VertexAttributes attributes;
  std::vector<GLuint> indices;
  bool flat_shading = false;  ///< face normals from the rasterised positions (no vertex normals)
  bool splats = false;        ///< a point cloud: one disc per index (attributes.size its radius)
  std::vector<float> lines;   ///< pairs of 3D points
  std::string label;
};

// --- options and text --------------------------------------------------------------------------

void check_options(PositionsRef V, FacesRef F, NormalsRef N,
                   const Eigen::Ref<const Eigen::VectorXd>& field, const FieldPictureOptions& o) {
  validate_mesh_arrays(V, F, N, "render_field_picture");
  const auto rows = std::to_string(V.rows());
  if (N.rows() != V.rows())
    throw InvalidInput("render_field_picture: N must have " + rows + " rows");
  if (field.size() != V.rows()) {
    throw InvalidInput("render_field_picture: the field has " + std::to_string(field.size()) +
                       " values for " + rows + " vertices");
  }
  if (o.width < kMinSize || o.height < kMinSize || o.width > kMaxSize || o.height > kMaxSize) {
    throw InvalidInput("render_field_picture: width and height must be in [64, 16384], got " +
                       std::to_string(o.width) + " x " + std::to_string(o.height));
  }
  if (o.range &&
      !(std::isfinite(o.range->lo) && std::isfinite(o.range->hi) && o.range->lo < o.range->hi)) {
    throw InvalidInput("render_field_picture: the range must be finite with lo < hi");
  }
  if (o.directions.rows() != 0 && o.directions.rows() != V.rows()) {
    throw InvalidInput("render_field_picture: directions must have 0 or " + rows + " rows");
  }
  if (o.glyph_count < 1) throw InvalidInput("render_field_picture: glyph_count must be >= 1");
  if (!(std::isfinite(o.splat_radius) && o.splat_radius >= 0.0)) {
    throw InvalidInput(
        "render_field_picture: splat_radius must be finite and >= 0 (0: from the "
        "spacing)");
  }
  if (o.focal_meshes) {
    for (const FocalMesh* g : {&o.focal_meshes->gamma1, &o.focal_meshes->gamma2}) {
      if (g->mesh.V.rows() != V.rows()) {
        throw InvalidInput("render_field_picture: a focal mesh must have the base mesh's " + rows +
                           " vertices");
      }
      validate_mesh_arrays(g->mesh.V, g->mesh.F, RowMatrixX3d(0, 3), "render_field_picture");
    }
  }
}

/// Tick label: 3 significant digits, "0" rather than "-0".
std::string number_text(double v) {
  if (v == 0.0) return "0";
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

struct Tick {
  double value;
  std::string text;
};

/// lo, lo/2, 0, hi/2, hi when the range holds 0 (the map's centre); else five even steps.
std::vector<Tick> colour_bar_ticks(const ColourRange& r) {
  std::vector<double> values;
  if (r.lo < 0.0 && r.hi > 0.0) {
    values = {r.lo, r.lo / 2.0, 0.0, r.hi / 2.0, r.hi};
  } else {
    for (int i = 0; i <= 4; ++i) values.push_back(r.lo + (r.hi - r.lo) * i / 4.0);
  }
  std::vector<Tick> ticks;
  for (double v : values) ticks.push_back({v, number_text(v)});
  return ticks;
}

constexpr PointClass kAllClasses[] = {PointClass::elliptic,  PointClass::hyperbolic,
                                      PointClass::parabolic, PointClass::umbilic,
                                      PointClass::flat,      PointClass::undefined};

// --- layout ----------------------------------------------------------------------------------

int legend_width(const FieldPictureOptions& o, const ColourRange& range, int s) {
  int text = 0;
  if (o.colour_map == ColourMap::classes) {
    for (PointClass c : kAllClasses) text = std::max(text, text_width(class_name(c), s));
    return 4 * s + 7 * s + 3 * s + text + 4 * s;  // margin, swatch, gap, name, margin
  }
  for (const Tick& t : colour_bar_ticks(range)) text = std::max(text, text_width(t.text, s));
  return 4 * s + 6 * s + 2 * s + 2 * s + text + 4 * s;  // margin, bar, tick, gap, label, margin
}

Layout plan_layout(const FieldPictureOptions& o, const ColourRange& range, int panel_count) {
  Layout l;
  l.scale = std::clamp(std::min(o.width, o.height) / 300, 1, 8);
  const int s = l.scale;
  const int title_height = o.title.empty() ? 0 : (kGlyphHeight + 6) * s;
  l.title = {0, 0, o.width, title_height};
  const int legend = std::min(legend_width(o, range, s), o.width / 2);
  l.legend = {o.width - legend, title_height, legend, o.height - title_height};
  const int label_height = panel_count > 1 ? (kGlyphHeight + 4) * s : 0;
  const int panel_width = (o.width - legend) / panel_count;
  for (int p = 0; p < panel_count; ++p) {
    l.labels.push_back({p * panel_width, title_height, panel_width, label_height});
    l.panels.push_back({p * panel_width, title_height + label_height, panel_width,
                        std::max(1, o.height - title_height - label_height)});
  }
  return l;
}

// --- scene -------------------------------------------------------------------------------------

std::vector<float> vertex_colours(const Eigen::Ref<const Eigen::VectorXd>& field, ColourMap map,
                                  const ColourRange& range) {
  std::vector<float> out(3 * static_cast<std::size_t>(field.size()));
  for (Eigen::Index i = 0; i < field.size(); ++i) {
    const Rgb c = map_colour(map, field[i], range);
    for (int k = 0; k < 3; ++k) out[3 * static_cast<std::size_t>(i) + k] = c[k] / 255.0f;
  }
  return out;
}

/// A well-mixed hash, so that the glyph subsample shows no pattern of the vertex order.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

double surface_area(PositionsRef V, FacesRef F) {
  double area = 0.0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const double twice = (b - a).cross(c - a).norm();
    if (std::isfinite(twice)) area += twice / 2.0;
  }
  return area;
}

// --- point clouds ------------------------------------------------------------------------------

/// Neighbours whose mean distance sets a splat's radius, and the radius relative to that mean.
/// On a hexagonal sampling of spacing s the mean distance to the 8 nearest is 1.18 s; discs of
/// radius 0.7 x 1.18 s = 0.83 s leave no gap on Poisson-disk samples (a disc radius of s / sqrt 3
/// would just cover a perfect lattice).
constexpr int kSplatNeighbours = 8;
constexpr double kSplatRadiusPerMeanDistance = 0.7;

/// Mean distance of each point to its 8 nearest (NaN for points with no neighbour).
Eigen::VectorXd mean_neighbour_distances(PositionsRef V) {
  Eigen::VectorXd mean =
      Eigen::VectorXd::Constant(V.rows(), std::numeric_limits<double>::quiet_NaN());
  const Neighbourhoods knn = nearest_neighbours(V, kSplatNeighbours);
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const auto begin = knn.offsets[i], end = knn.offsets[i + 1];
    if (begin == end) continue;
    double sum = 0.0;
    for (auto k = begin; k < end; ++k) sum += (V.row(knn.indices[k]) - V.row(i)).norm();
    mean[i] = sum / static_cast<double>(end - begin);
  }
  return mean;
}

/// Splat radius per point: `radius` for all, or (radius 0) 0.7 x the mean distance to the 8
/// nearest; a point without neighbours gets 1% of the bounding box diagonal.
std::vector<float> splat_radii(PositionsRef V, double radius) {
  std::vector<float> out(static_cast<std::size_t>(V.rows()), static_cast<float>(radius));
  if (radius > 0.0) return out;
  const Eigen::VectorXd mean = mean_neighbour_distances(V);
  const double fallback = 0.01 * bounding_box_diagonal(V);
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const double r =
        std::isfinite(mean[i]) && mean[i] > 0.0 ? kSplatRadiusPerMeanDistance * mean[i] : fallback;
    out[static_cast<std::size_t>(i)] = static_cast<float>(r);
  }
  return out;
}

/// Indices of the points that can be drawn: finite positions (a non-finite normal only turns
/// the splat towards the eye).
std::vector<GLuint> drawable_points(PositionsRef V) {
  std::vector<GLuint> indices;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (V.row(i).allFinite()) indices.push_back(static_cast<GLuint>(i));
  }
  return indices;
}

/// Float normals with non-finite rows zeroed: the splat shader turns those towards the eye.
std::vector<float> splat_normals(NormalsRef N, Eigen::Index count) {
  std::vector<float> out(3 * static_cast<std::size_t>(count), 0.0f);
  if (N.rows() != count) return out;
  for (Eigen::Index i = 0; i < count; ++i) {
    if (!N.row(i).allFinite()) continue;
    for (int c = 0; c < 3; ++c)
      out[3 * static_cast<std::size_t>(i) + c] = static_cast<float>(N(i, c));
  }
  return out;
}

/// A point cloud's panel: one disc per drawable point.
PanelContent splat_panel(PositionsRef V, NormalsRef N, const std::vector<float>& colours,
                         const FieldPictureOptions& o) {
  PanelContent p;
  p.attributes = {render_detail::to_floats(V), splat_normals(N, V.rows()), colours,
                  splat_radii(V, o.splat_radius)};
  p.indices = drawable_points(V);
  p.splats = true;
  return p;
}

/// Area a cloud samples: each splat's share, (splat radius / 0.7 / 1.18)^2 x sqrt(3) / 2 (the
/// cell of a hexagonal sampling of that spacing).
double cloud_area(const std::vector<float>& radii) {
  double area = 0.0;
  for (float r : radii) {
    const double s = r / (kSplatRadiusPerMeanDistance * 1.18);
    area += s * s * std::sqrt(3.0) / 2.0;
  }
  return area;
}

/// Segments p -/+ h d through about `count` vertices, h 0.4 of the spacing between the chosen
/// vertices (so that neighbouring glyphs do not touch), lifted off the surface by h / 4 along
/// the normal so that curved surfaces do not hide them.
std::vector<float> direction_glyphs(PositionsRef V, double area, NormalsRef N,
                                    const RowMatrixX3d& directions, int count) {
  std::vector<float> lines;
  if (directions.rows() == 0 || V.rows() == 0) return lines;
  const double fraction = std::min(1.0, static_cast<double>(count) / static_cast<double>(V.rows()));
  // fraction * 2^64 as an integer; at fraction 1 that is out of range (undefined behaviour,
  // which gave threshold 0 and no glyphs in the sanitizer build), so all vertices are taken.
  const std::uint64_t threshold = fraction >= 1.0
                                      ? std::numeric_limits<std::uint64_t>::max()
                                      : static_cast<std::uint64_t>(std::ldexp(fraction, 64));
  const double spacing = std::sqrt(area / (fraction * static_cast<double>(V.rows())));
  const double h = 0.4 * spacing;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (mix(static_cast<std::uint64_t>(i)) > threshold) continue;
    const Eigen::Vector3d p = V.row(i), n = N.row(i), d = directions.row(i);
    if (!p.allFinite() || !n.allFinite() || !d.allFinite() || d.norm() == 0.0) continue;
    const Eigen::Vector3d centre = p + 0.25 * h * (n.norm() > 0.0 ? n.normalized() : n);
    const Eigen::Vector3d half = h * d.normalized();
    for (const Eigen::Vector3d& end :
         {Eigen::Vector3d(centre - half), Eigen::Vector3d(centre + half)}) {
      for (int c = 0; c < 3; ++c) lines.push_back(static_cast<float>(end[c]));
    }
  }
  return lines;
}

std::vector<PanelContent> panel_contents(PositionsRef V, FacesRef F, NormalsRef N,
                                         const std::vector<float>& colours,
                                         const FieldPictureOptions& o) {
  std::vector<PanelContent> panels(1);
  if (F.rows() == 0) {
    panels[0] = splat_panel(V, N, colours, o);
    panels[0].lines =
        direction_glyphs(V, cloud_area(panels[0].attributes.size), N, o.directions, o.glyph_count);
  } else {
    panels[0].attributes = {render_detail::to_floats(V), render_detail::to_floats(N), colours, {}};
    panels[0].indices = render_detail::drawable_faces(V, F, N);
    panels[0].lines = direction_glyphs(V, surface_area(V, F), N, o.directions, o.glyph_count);
  }
  panels[0].label = "surface";
  if (!o.focal_meshes) return panels;
  const char* labels[] = {"focal mesh 1 (k1)", "focal mesh 2 (k2)"};
  int j = 0;
  for (const FocalMesh* g : {&o.focal_meshes->gamma1, &o.focal_meshes->gamma2}) {
    PanelContent p;
    if (g->mesh.F.rows() == 0) {  // the focal points of a cloud: splats facing the eye
      p = splat_panel(g->mesh.V, RowMatrixX3d(0, 3), colours, o);
      p.label = j == 0 ? "focal points 1 (k1)" : "focal points 2 (k2)";
    } else {
      p.attributes = {render_detail::to_floats(g->mesh.V), {}, colours, {}};
      p.indices = render_detail::drawable_faces(g->mesh.V, g->mesh.F, RowMatrixX3d(0, 3));
      p.flat_shading = true;
    }
    if (p.label.empty()) p.label = labels[j];
    ++j;
    panels.push_back(std::move(p));
  }
  return panels;
}

// --- OpenGL ------------------------------------------------------------------------------------

constexpr const char* kSurfaceVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 colour;
uniform mat4 view_projection;
out vec3 world_position;
out vec3 world_normal;
out vec3 vertex_colour;
void main() {
  world_position = position;
  world_normal = normal;
  vertex_colour = colour;
  gl_Position = view_projection * vec4(position, 1.0);
}
)";

// Lambert under a headlight; |cos| so that back faces (open meshes, focal meshes) are lit too.
constexpr const char* kSurfaceFragmentShader = R"(#version 330 core
in vec3 world_position;
in vec3 world_normal;
in vec3 vertex_colour;
uniform vec3 eye;
uniform vec3 towards_eye;
uniform int orthographic;
uniform int flat_shading;
uniform float ambient;
out vec4 fragment;
void main() {
  vec3 n = flat_shading != 0 ? cross(dFdx(world_position), dFdy(world_position)) : world_normal;
  vec3 v = orthographic != 0 ? towards_eye : eye - world_position;
  float ln = length(n);
  float lv = length(v);
  float lambert = (ln > 0.0 && lv > 0.0) ? abs(dot(n, v)) / (ln * lv) : 1.0;
  fragment = vec4(vertex_colour * (ambient + (1.0 - ambient) * lambert), 1.0);
}
)";

// Splats: each point becomes an octagon of its radius in the plane normal to its normal (or
// facing the eye where it has none), drawn with the surface fragment shader and depth-tested.
constexpr const char* kSplatVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 colour;
layout(location = 3) in float radius;
out vec3 point_position;
out vec3 point_normal;
out vec3 point_colour;
out float point_radius;
void main() {
  point_position = position;
  point_normal = normal;
  point_colour = colour;
  point_radius = radius;
}
)";

constexpr const char* kSplatGeometryShader = R"(#version 330 core
layout(points) in;
layout(triangle_strip, max_vertices = 8) out;
in vec3 point_position[];
in vec3 point_normal[];
in vec3 point_colour[];
in float point_radius[];
uniform mat4 view_projection;
uniform vec3 eye;
uniform vec3 towards_eye;
uniform int orthographic;
out vec3 world_position;
out vec3 world_normal;
out vec3 vertex_colour;
void main() {
  vec3 p = point_position[0];
  vec3 n = point_normal[0];
  if (!(dot(n, n) > 0.0)) n = orthographic != 0 ? towards_eye : eye - p;
  n = normalize(n);
  vec3 a = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
  vec3 u = normalize(cross(n, a));
  vec3 w = cross(n, u);
  // The octagon's corners in strip order: 0 1 7 2 6 3 5 4.
  const int corner[8] = int[8](0, 1, 7, 2, 6, 3, 5, 4);
  for (int k = 0; k < 8; ++k) {
    float t = float(corner[k]) * 0.7853981634;
    vec3 q = p + point_radius[0] * (cos(t) * u + sin(t) * w);
    world_position = q;
    world_normal = n;
    vertex_colour = point_colour[0];
    gl_Position = view_projection * vec4(q, 1.0);
    EmitVertex();
  }
  EndPrimitive();
}
)";

constexpr const char* kLineVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 view_projection;
void main() { gl_Position = view_projection * vec4(position, 1.0); }
)";

constexpr const char* kLineFragmentShader = R"(#version 330 core
uniform vec3 colour;
out vec4 fragment;
void main() { fragment = vec4(colour, 1.0); }
)";

/// Colour and depth renderbuffers with `samples` samples (0 = single-sampled) in a new
/// framebuffer, left bound; 0 (nothing left allocated) when the driver cannot make it complete
/// (out of its memory: a large picture with many samples).
GLuint try_colour_framebuffer(int width, int height, int samples) {
  GLuint framebuffer = 0;
  glGenFramebuffers(1, &framebuffer);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  const GLenum formats[] = {GL_RGBA8, GL_DEPTH_COMPONENT24};
  const GLenum attachments[] = {GL_COLOR_ATTACHMENT0, GL_DEPTH_ATTACHMENT};
  GLuint renderbuffers[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    GLuint renderbuffer = 0;
    glGenRenderbuffers(1, &renderbuffer);
    glBindRenderbuffer(GL_RENDERBUFFER, renderbuffer);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, formats[k], width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachments[k], GL_RENDERBUFFER, renderbuffer);
    renderbuffers[k] = renderbuffer;
  }
  const bool complete = glGetError() == GL_NO_ERROR &&
                        glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  if (complete) return framebuffer;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteRenderbuffers(2, renderbuffers);
  glDeleteFramebuffers(1, &framebuffer);
  while (glGetError() != GL_NO_ERROR) {
  }
  return 0;
}

/// Bytes of a width x height colour (RGBA8) and depth (24 bits, stored in 32) framebuffer with
/// `samples` samples per pixel (0: one).
std::uint64_t framebuffer_bytes(int width, int height, int samples) {
  return static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) * 8u *
         static_cast<std::uint64_t>(std::max(1, samples));
}

void set_vector(GLuint program, const char* name, const Eigen::Vector3d& v) {
  glUniform3f(glGetUniformLocation(program, name), static_cast<float>(v.x()),
              static_cast<float>(v.y()), static_cast<float>(v.z()));
}

struct Programs {
  GLuint surface = 0;
  GLuint lines = 0;
  GLuint splats = 0;
};

void draw_panel(const PanelContent& panel, const Rect& r, int picture_height, const Camera& camera,
                const Programs& programs) {
  // OpenGL's viewport origin is the bottom-left corner.
  glViewport(r.x, picture_height - r.y - r.height, r.width, r.height);
  const Eigen::Matrix4f view_projection =
      view_projection_matrix(camera, static_cast<double>(r.width) / r.height).cast<float>();
  const GLuint program = panel.splats ? programs.splats : programs.surface;
  glUseProgram(program);
  glUniformMatrix4fv(glGetUniformLocation(program, "view_projection"), 1, GL_FALSE,
                     view_projection.data());
  set_vector(program, "eye", camera.eye);
  set_vector(program, "towards_eye", (camera.eye - camera.target).normalized());
  glUniform1i(glGetUniformLocation(program, "orthographic"),
              camera.projection == Projection::orthographic);
  glUniform1i(glGetUniformLocation(program, "flat_shading"), panel.flat_shading);
  glUniform1f(glGetUniformLocation(program, "ambient"), kAmbient);
  const GLsizei count = render_detail::upload_mesh(panel.attributes, panel.indices);
  // Surfaces are pushed back in depth so that glyphs lying on them win the depth test.
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 1.0f);
  glDrawElements(panel.splats ? GL_POINTS : GL_TRIANGLES, count, GL_UNSIGNED_INT, nullptr);
  glDisable(GL_POLYGON_OFFSET_FILL);
  if (panel.lines.empty()) return;
  glUseProgram(programs.lines);
  glUniformMatrix4fv(glGetUniformLocation(programs.lines, "view_projection"), 1, GL_FALSE,
                     view_projection.data());
  glUniform3f(glGetUniformLocation(programs.lines, "colour"), kGlyphGrey, kGlyphGrey, kGlyphGrey);
  render_detail::VertexAttributes line_points;
  line_points.position = panel.lines;
  std::vector<GLuint> order(panel.lines.size() / 3);
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<GLuint>(k);
  const GLsizei points = render_detail::upload_mesh(line_points, order);
  glDrawElements(GL_LINES, points, GL_UNSIGNED_INT, nullptr);
}

/// The panels rendered into a width x height picture on the background colour.
Image render_panels(const std::vector<PanelContent>& panels, const Layout& layout,
                    const Camera& camera, const FieldPictureOptions& o) {
  render_detail::GlContext gl;
  if (std::max(o.width, o.height) > render_detail::max_framebuffer_size()) {
    throw RenderError("render_field_picture: " + std::to_string(o.width) + " x " +
                      std::to_string(o.height) + " is over this driver's framebuffer limit (" +
                      gl.description() + ")");
  }
  GLint max_samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  int samples = o.samples > 1 ? std::min(o.samples, static_cast<int>(max_samples)) : 0;
  // The resolved picture, its copy read back and the RGB image: needed whatever the samples.
  const std::string picture =
      "render_field_picture: a " + std::to_string(o.width) + " x " + std::to_string(o.height) +
      " picture";
  const std::uint64_t pixels =
      static_cast<std::uint64_t>(o.width) * static_cast<std::uint64_t>(o.height);
  detail::require_memory(framebuffer_bytes(o.width, o.height, 0) + pixels * 7, picture);
  const GLuint resolved = try_colour_framebuffer(o.width, o.height, 0);
  if (resolved == 0) {
    throw RenderError(picture + ": the OpenGL driver (" + gl.description() +
                      ") cannot allocate its framebuffer (" +
                      detail::memory_text(framebuffer_bytes(o.width, o.height, 0)) +
                      "); a smaller size fits");
  }
  // Fewer samples where the driver (or the machine) has no memory for as many: the same picture,
  // less smoothed edges, rather than no picture.
  GLuint drawn = resolved;
  const std::uint64_t available = detail::available_memory();
  for (; samples > 1; samples /= 2) {
    if (available != 0 && framebuffer_bytes(o.width, o.height, samples) > available / 2) continue;
    drawn = try_colour_framebuffer(o.width, o.height, samples);
    if (drawn != 0) break;
  }
  if (drawn == 0) drawn = resolved;
  if (samples != std::min(o.samples, static_cast<int>(max_samples)) && o.samples > 1) {
    if (const auto& warn = current_execution().warning) {
      warn(picture + ": the driver (or the machine's memory) cannot hold " +
           std::to_string(o.samples) + " samples per pixel at this size; drawn with " +
           std::to_string(std::max(samples, 1)));
    }
  }
  glBindFramebuffer(GL_FRAMEBUFFER, drawn);
  glClearColor(kBackground[0] / 255.0f, kBackground[1] / 255.0f, kBackground[2] / 255.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_SCISSOR_TEST);  // a panel's far-reaching focal points stay in their panel
  const Programs programs{
      render_detail::build_program(kSurfaceVertexShader, kSurfaceFragmentShader),
      render_detail::build_program(kLineVertexShader, kLineFragmentShader),
      render_detail::build_program(kSplatVertexShader, kSurfaceFragmentShader,
                                   kSplatGeometryShader)};
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const Rect& r = layout.panels[p];
    glScissor(r.x, o.height - r.y - r.height, r.width, r.height);
    draw_panel(panels[p], r, o.height, camera, programs);
  }
  glDisable(GL_SCISSOR_TEST);
  require_no_gl_error("drawing the picture");
  if (drawn != resolved) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, drawn);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolved);
    glBlitFramebuffer(0, 0, o.width, o.height, 0, 0, o.width, o.height, GL_COLOR_BUFFER_BIT,
                      GL_NEAREST);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolved);
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(o.width) * o.height * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, o.width, o.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  require_no_gl_error("reading the picture");
  Image image{o.width, o.height,
              std::vector<std::uint8_t>(static_cast<std::size_t>(o.width) * o.height * 3)};
  for (int y = 0; y < o.height; ++y) {
    const std::size_t from_row = static_cast<std::size_t>(o.height - 1 - y) * o.width;
    for (int x = 0; x < o.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        image.rgb[3 * (static_cast<std::size_t>(y) * o.width + x) + c] =
            rgba[4 * (from_row + x) + c];
      }
    }
  }
  return image;
}

// --- 2D overlays -------------------------------------------------------------------------------

void fill(Image& image, const Rect& r, Rgb colour) {
  for (int y = std::max(r.y, 0); y < std::min(r.y + r.height, image.height); ++y) {
    for (int x = std::max(r.x, 0); x < std::min(r.x + r.width, image.width); ++x) {
      std::copy(colour.begin(), colour.end(),
                image.rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(y) * image.width + x));
    }
  }
}

void outline(Image& image, const Rect& r, Rgb colour) {
  fill(image, {r.x - 1, r.y - 1, r.width + 2, 1}, colour);
  fill(image, {r.x - 1, r.y + r.height, r.width + 2, 1}, colour);
  fill(image, {r.x - 1, r.y, 1, r.height}, colour);
  fill(image, {r.x + r.width, r.y, 1, r.height}, colour);
}

/// A vertical bar, hi at the top, linear in value, ticks and labels on its right.
void draw_colour_bar(Image& image, const Rect& strip, const ColourRange& range, int s) {
  const int glyph = kGlyphHeight * s;
  const Rect bar{strip.x + 4 * s, strip.y + strip.height / 8, 6 * s,
                 std::max(2, strip.height * 3 / 4)};
  for (int row = 0; row < bar.height; ++row) {
    const double t = static_cast<double>(row) / (bar.height - 1);
    const double value = range.hi - t * (range.hi - range.lo);
    fill(image, {bar.x, bar.y + row, bar.width, 1}, map_colour(ColourMap::diverging, value, range));
  }
  outline(image, bar, kInk);
  for (const Tick& tick : colour_bar_ticks(range)) {
    const double t = (range.hi - tick.value) / (range.hi - range.lo);
    const int y = bar.y + static_cast<int>(std::lround(t * (bar.height - 1)));
    fill(image, {bar.x + bar.width, y - s / 2, 2 * s, std::max(1, s / 2 + 1)}, kInk);
    draw_text(image, bar.x + bar.width + 4 * s, y - glyph / 2, tick.text, s, kInk);
  }
}

void draw_class_legend(Image& image, const Rect& strip, int s) {
  const int row_height = (kGlyphHeight + 5) * s;
  const int rows = static_cast<int>(std::size(kAllClasses));
  int y = strip.y + std::max(0, (strip.height - rows * row_height) / 2);
  for (PointClass c : kAllClasses) {
    const Rect swatch{strip.x + 4 * s, y, 7 * s, 7 * s};
    fill(image, swatch, map_colour(ColourMap::classes, static_cast<double>(c), {}));
    outline(image, swatch, kInk);
    draw_text(image, swatch.x + swatch.width + 3 * s, y, class_name(c), s, kInk);
    y += row_height;
  }
}

void draw_overlays(Image& image, const Layout& layout, const std::vector<PanelContent>& panels,
                   const FieldPictureOptions& o, const ColourRange& range) {
  const int s = layout.scale;
  fill(image, layout.legend, kBackground);  // nothing of a panel reaches into the legend
  if (!o.title.empty()) draw_text(image, 4 * s, 3 * s, o.title, s, kInk);
  if (panels.size() > 1) {
    for (std::size_t p = 0; p < panels.size(); ++p) {
      draw_text(image, layout.labels[p].x + 4 * s, layout.labels[p].y + 2 * s, panels[p].label, s,
                kInk);
    }
  }
  if (o.colour_map == ColourMap::classes) {
    draw_class_legend(image, layout.legend, s);
  } else {
    draw_colour_bar(image, layout.legend, range, s);
  }
}

}  // namespace

Image render_field_picture(PositionsRef V, FacesRef F, NormalsRef N,
                           const Eigen::Ref<const Eigen::VectorXd>& field,
                           const FieldPictureOptions& options) {
  check_options(V, F, N, field, options);
  const ColourRange range =
      options.range ? *options.range : robust_symmetric_range(field, options.range_percentile);
  const Camera camera = options.camera ? *options.camera : fit_camera(V, options.view);
  const std::vector<PanelContent> panels =
      panel_contents(V, F, N, vertex_colours(field, options.colour_map, range), options);
  const Layout layout = plan_layout(options, range, static_cast<int>(panels.size()));
  (void)view_projection_matrix(camera, 1.0);  // rejects an invalid camera before any GL work
  Image image = render_panels(panels, layout, camera, options);
  draw_overlays(image, layout, panels, options, range);
  return image;
}

}  // namespace focal
