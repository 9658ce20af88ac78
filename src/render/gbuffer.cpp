// G-buffers: world positions and interpolated unit normals in two RGBA32F attachments.
#include <algorithm>
#include <string>

#include "focal/render/render.h"
#include "render/gl_context.h"
#include "render/gl_mesh.h"

namespace focal {
namespace {

using render_detail::require_complete_framebuffer;
using render_detail::require_no_gl_error;

constexpr int kMaxSize = 16384;

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
uniform mat4 view_projection;
out vec3 world_position;
out vec3 world_normal;
void main() {
  world_position = position;
  world_normal = normal;
  gl_Position = view_projection * vec4(position, 1.0);
}
)";

// Alpha 1 in the position attachment marks coverage (cleared to 0).
constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 world_position;
in vec3 world_normal;
layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
void main() {
  out_position = vec4(world_position, 1.0);
  out_normal = vec4(normalize(world_normal), 0.0);
}
)";

void attach_renderbuffer(GLenum attachment, GLenum format, int width, int height) {
  GLuint renderbuffer = 0;
  glGenRenderbuffers(1, &renderbuffer);
  glBindRenderbuffer(GL_RENDERBUFFER, renderbuffer);
  glRenderbufferStorage(GL_RENDERBUFFER, format, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, renderbuffer);
}

void make_gbuffer_framebuffer(int width, int height) {
  GLuint framebuffer = 0;
  glGenFramebuffers(1, &framebuffer);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  attach_renderbuffer(GL_COLOR_ATTACHMENT0, GL_RGBA32F, width, height);
  attach_renderbuffer(GL_COLOR_ATTACHMENT1, GL_RGBA32F, width, height);
  // 32-bit float depth: the nearest surface wins even where layers are close.
  attach_renderbuffer(GL_DEPTH_ATTACHMENT, GL_DEPTH_COMPONENT32F, width, height);
  const GLenum draw_buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, draw_buffers);
  require_no_gl_error("G-buffer framebuffer");
  require_complete_framebuffer("G-buffer framebuffer");
}

/// Reads one RGBA32F attachment, bottom row first as OpenGL stores it.
std::vector<float> read_attachment(GLenum attachment, int width, int height) {
  std::vector<float> rgba(static_cast<std::size_t>(width) * height * 4);
  glReadBuffer(attachment);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba.data());
  require_no_gl_error("reading the G-buffer");
  return rgba;
}

/// Repacks GL's bottom-up RGBA into the top-down 3-per-pixel layout of GBuffer.
void unpack(const std::vector<float>& position_rgba, const std::vector<float>& normal_rgba,
            GBuffer& out) {
  const std::size_t pixels = static_cast<std::size_t>(out.width) * out.height;
  out.position.assign(3 * pixels, 0.0f);
  out.normal.assign(3 * pixels, 0.0f);
  out.mask.assign(pixels, 0);
  for (int y = 0; y < out.height; ++y) {
    const std::size_t gl_row = static_cast<std::size_t>(out.height - 1 - y) * out.width;
    for (int x = 0; x < out.width; ++x) {
      const std::size_t from = gl_row + x;
      const std::size_t to = static_cast<std::size_t>(y) * out.width + x;
      if (!(position_rgba[4 * from + 3] > 0.5f)) continue;
      out.mask[to] = 1;
      for (int c = 0; c < 3; ++c) {
        out.position[3 * to + c] = position_rgba[4 * from + c];
        out.normal[3 * to + c] = normal_rgba[4 * from + c];
      }
    }
  }
}

}  // namespace

GBuffer rasterise_gbuffer(PositionsRef V, FacesRef F, NormalsRef N, const Camera& camera, int width,
                          int height) {
  validate_mesh_arrays(V, F, N, "rasterise_gbuffer");
  if (N.rows() != V.rows()) {
    throw InvalidInput("rasterise_gbuffer: N must have one row per vertex (" +
                       std::to_string(V.rows()) + "), got " + std::to_string(N.rows()));
  }
  if (width < 1 || height < 1 || width > kMaxSize || height > kMaxSize) {
    throw InvalidInput("rasterise_gbuffer: width and height must be in [1, 16384], got " +
                       std::to_string(width) + " x " + std::to_string(height));
  }
  const Eigen::Matrix4f view_projection =
      view_projection_matrix(camera, static_cast<double>(width) / height).cast<float>();

  render_detail::GlContext gl;
  if (std::max(width, height) > render_detail::max_framebuffer_size()) {
    throw RenderError("rasterise_gbuffer: " + std::to_string(width) + " x " +
                      std::to_string(height) + " is over this driver's framebuffer limit (" +
                      gl.description() + ")");
  }
  make_gbuffer_framebuffer(width, height);
  const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  glClearBufferfv(GL_COLOR, 0, zero);
  glClearBufferfv(GL_COLOR, 1, zero);
  glClear(GL_DEPTH_BUFFER_BIT);
  glViewport(0, 0, width, height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);

  const GLuint program = render_detail::build_program(kVertexShader, kFragmentShader);
  glUseProgram(program);
  glUniformMatrix4fv(glGetUniformLocation(program, "view_projection"), 1, GL_FALSE,
                     view_projection.data());
  const GLsizei count = render_detail::upload_mesh({.position = render_detail::to_floats(V),
                                                    .normal = render_detail::to_floats(N),
                                                    .colour = {},
                                                    .size = {}},
                                                   render_detail::drawable_faces(V, F, N));
  glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, nullptr);
  require_no_gl_error("drawing the G-buffer");

  GBuffer out;
  out.width = width;
  out.height = height;
  unpack(read_attachment(GL_COLOR_ATTACHMENT0, width, height),
         read_attachment(GL_COLOR_ATTACHMENT1, width, height), out);
  return out;
}

}  // namespace focal
