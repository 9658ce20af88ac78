#pragma once
// A headless OpenGL 3.3 core context through EGL, current on the calling thread for the lifetime
// of a GlContext, and the few GL helpers the renderers share. GL functions are linked directly
// from GLVND's libOpenGL (GL_GLEXT_PROTOTYPES), so there is no loader.

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <string>

namespace focal::render_detail {

class GlContext {
 public:
  /// \throw RenderError naming each EGL platform tried and why it failed.
  GlContext();
  /// Releases and destroys the context (with every GL object made in it) and makes the context
  /// that was current before, if any, current again.
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  /// "EGL <platform>, <GL_VERSION>, <GL_RENDERER>", for messages.
  [[nodiscard]] std::string description() const;

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
  void* surface_ = nullptr;  // a 1 x 1 pbuffer where surfaceless contexts are not supported
  void* previous_display_ = nullptr;
  void* previous_context_ = nullptr;
  void* previous_draw_ = nullptr;
  void* previous_read_ = nullptr;
};

/// Compiles and links a GLSL program. \throw RenderError with the driver's log.
[[nodiscard]] GLuint build_program(const char* vertex_source, const char* fragment_source,
                                   const char* geometry_source = nullptr);

/// \throw RenderError naming `what` unless the bound draw framebuffer is complete.
void require_complete_framebuffer(const char* what);

/// \throw RenderError naming `what` when glGetError reports an error (out of memory, a size
/// over the driver's limits...).
void require_no_gl_error(const char* what);

/// A framebuffer's size limit on this driver (GL_MAX_RENDERBUFFER_SIZE and the viewport limit).
[[nodiscard]] int max_framebuffer_size();

}  // namespace focal::render_detail
