// EGL without a display server. The display is chosen once per process, trying in order:
//  1. EGL_EXT_platform_device: each EGL device (an NVIDIA GPU, or Mesa's software device),
//  2. EGL_MESA_platform_surfaceless (Mesa, also without /dev/dri),
//  3. eglGetDisplay(EGL_DEFAULT_DISPLAY) (older drivers; may need a display server).
// The first on which an OpenGL 3.3 core context can be created and made current wins.
#include "render/gl_context.h"

// Keep X11 headers (and their macros such as None and Status) out: nothing here needs them.
#define EGL_NO_X11 1
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <vector>

#include "focal/render/render.h"

namespace focal::render_detail {
namespace {

std::string hex(unsigned value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%04x", value);
  return text;
}

std::string egl_error() { return "EGL error " + hex(static_cast<unsigned>(eglGetError())); }

bool has_extension(const char* list, const std::string& name) {
  if (list == nullptr) return false;
  const std::string all = std::string(" ") + list + " ";
  return all.find(" " + name + " ") != std::string::npos;
}

/// A context, and the surface it was made current with (EGL_NO_SURFACE where surfaceless
/// contexts work), current on this thread.
struct CurrentContext {
  EGLContext context = EGL_NO_CONTEXT;
  EGLSurface surface = EGL_NO_SURFACE;
};

/// A config for an OpenGL context with a pbuffer (for the fallback surface); else any OpenGL
/// config; else EGL_NO_CONFIG_KHR where the display allows contexts without one.
bool choose_config(EGLDisplay display, EGLConfig& config, std::string& why) {
  const EGLint surface_types[] = {EGL_PBUFFER_BIT, 0};
  for (const EGLint surface_type : surface_types) {
    const EGLint attributes[] = {EGL_SURFACE_TYPE, surface_type, EGL_RENDERABLE_TYPE,
                                 EGL_OPENGL_BIT, EGL_NONE};
    EGLint count = 0;
    if (eglChooseConfig(display, attributes, &config, 1, &count) && count > 0) return true;
  }
  if (has_extension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_no_config_context")) {
    config = EGL_NO_CONFIG_KHR;
    return true;
  }
  why = "no EGL config renders with OpenGL";
  return false;
}

/// Creates an OpenGL 3.3 core context on `display` and makes it current.
bool make_current_context(EGLDisplay display, CurrentContext& out, std::string& why) {
  if (!eglBindAPI(EGL_OPENGL_API)) {
    why = "eglBindAPI(EGL_OPENGL_API) failed (" + egl_error() + ")";
    return false;
  }
  EGLConfig config{};
  if (!choose_config(display, config, why)) return false;
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                               3,
                               EGL_CONTEXT_MINOR_VERSION,
                               3,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                               EGL_NONE};
  out.context = eglCreateContext(display, config, EGL_NO_CONTEXT, attributes);
  if (out.context == EGL_NO_CONTEXT) {
    why = "no OpenGL 3.3 core context (" + egl_error() + ")";
    return false;
  }
  if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, out.context)) return true;
  // Without EGL_KHR_surfaceless_context a context needs a surface: a 1 x 1 pbuffer (all
  // rendering goes to framebuffer objects anyway).
  const EGLint pbuffer_size[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
  if (config != EGL_NO_CONFIG_KHR) {
    out.surface = eglCreatePbufferSurface(display, config, pbuffer_size);
  }
  if (out.surface != EGL_NO_SURFACE &&
      eglMakeCurrent(display, out.surface, out.surface, out.context)) {
    return true;
  }
  why = "the context cannot be made current without a window (" + egl_error() + ")";
  if (out.surface != EGL_NO_SURFACE) eglDestroySurface(display, out.surface);
  eglDestroyContext(display, out.context);
  out = {};
  return false;
}

/// Initialises `display` and checks that a context works on it (then destroys the test context).
bool usable(EGLDisplay display, const std::string& name, std::string& failures) {
  std::string why;
  EGLint major = 0, minor = 0;
  if (display == EGL_NO_DISPLAY) {
    why = "no display (" + egl_error() + ")";
  } else if (!eglInitialize(display, &major, &minor)) {
    why = "eglInitialize failed (" + egl_error() + ")";
  } else {
    CurrentContext probe;
    if (make_current_context(display, probe, why)) {
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      if (probe.surface != EGL_NO_SURFACE) eglDestroySurface(display, probe.surface);
      eglDestroyContext(display, probe.context);
      return true;
    }
  }
  failures += "\n  " + name + ": " + why;
  return false;
}

struct ChosenDisplay {
  EGLDisplay display = EGL_NO_DISPLAY;
  std::string platform;
};

ChosenDisplay find_display() {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  const auto query_devices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  std::string failures;
  if (get_platform_display && query_devices && has_extension(client, "EGL_EXT_platform_device")) {
    std::vector<EGLDeviceEXT> devices(16);
    EGLint count = 0;
    if (query_devices(static_cast<EGLint>(devices.size()), devices.data(), &count)) {
      for (EGLint i = 0; i < count; ++i) {
        const std::string name = "EGL_EXT_platform_device, device " + std::to_string(i);
        EGLDisplay d = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (usable(d, name, failures)) return {d, name};
      }
    }
    if (count == 0) failures += "\n  EGL_EXT_platform_device: no EGL device";
  } else {
    failures += "\n  EGL_EXT_platform_device: not supported by this EGL";
  }
  if (get_platform_display && has_extension(client, "EGL_MESA_platform_surfaceless")) {
    const std::string name = "EGL_MESA_platform_surfaceless";
    EGLDisplay d =
        get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (usable(d, name, failures)) return {d, name};
  } else {
    failures += "\n  EGL_MESA_platform_surfaceless: not supported by this EGL";
  }
  EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  if (usable(d, "EGL_DEFAULT_DISPLAY", failures)) return {d, "EGL_DEFAULT_DISPLAY"};
  throw RenderError(
      "no headless OpenGL 3.3 context: tried" + failures +
      "\n(install Mesa's EGL and GL drivers, e.g. libegl-mesa0 libgl1-mesa-dri, or a GPU driver)");
}

/// The display, found once per process; a failed search is repeated on the next call.
const ChosenDisplay& chosen_display() {
  static std::mutex mutex;
  static ChosenDisplay chosen;
  const std::lock_guard lock(mutex);
  if (chosen.display == EGL_NO_DISPLAY) chosen = find_display();
  return chosen;
}

}  // namespace

GlContext::GlContext() {
  const ChosenDisplay& chosen = chosen_display();
  previous_display_ = eglGetCurrentDisplay();
  previous_context_ = eglGetCurrentContext();
  previous_draw_ = eglGetCurrentSurface(EGL_DRAW);
  previous_read_ = eglGetCurrentSurface(EGL_READ);
  CurrentContext current;
  std::string why;
  if (!make_current_context(chosen.display, current, why)) {
    throw RenderError("OpenGL context on " + chosen.platform + ": " + why);
  }
  display_ = chosen.display;
  context_ = current.context;
  surface_ = current.surface;
}

GlContext::~GlContext() {
  if (previous_context_ != EGL_NO_CONTEXT) {
    eglMakeCurrent(previous_display_, previous_draw_, previous_read_, previous_context_);
  } else {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  if (surface_ != EGL_NO_SURFACE) eglDestroySurface(display_, surface_);
  eglDestroyContext(display_, context_);
}

std::string GlContext::description() const {
  const auto text = [](GLenum name) {
    const auto* s = reinterpret_cast<const char*>(glGetString(name));
    return std::string(s ? s : "?");
  };
  return "EGL " + chosen_display().platform + ", OpenGL " + text(GL_VERSION) + ", " +
         text(GL_RENDERER);
}

GLuint build_program(const char* vertex_source, const char* fragment_source,
                     const char* geometry_source) {
  const auto compile = [](GLenum type, const char* source) {
    const GLuint shader = glCreateShader(type);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      char log[2048] = {};
      glGetShaderInfoLog(shader, sizeof log, nullptr, log);
      throw RenderError(std::string("GLSL shader does not compile: ") + log);
    }
    return shader;
  };
  const GLuint program = glCreateProgram();
  glAttachShader(program, compile(GL_VERTEX_SHADER, vertex_source));
  glAttachShader(program, compile(GL_FRAGMENT_SHADER, fragment_source));
  if (geometry_source != nullptr)
    glAttachShader(program, compile(GL_GEOMETRY_SHADER, geometry_source));
  glLinkProgram(program);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    throw RenderError(std::string("GLSL program does not link: ") + log);
  }
  return program;
}

void require_complete_framebuffer(const char* what) {
  const GLenum status = glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw RenderError(std::string(what) + ": framebuffer incomplete (status " + hex(status) + ")");
  }
}

void require_no_gl_error(const char* what) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    throw RenderError(std::string(what) + ": OpenGL error " + hex(error));
  }
}

int max_framebuffer_size() {
  GLint renderbuffer = 0;
  GLint viewport[2] = {0, 0};
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &renderbuffer);
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, viewport);
  return std::min({renderbuffer, viewport[0], viewport[1]});
}

}  // namespace focal::render_detail
