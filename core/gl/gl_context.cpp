// gl_context.cpp — see gl_context.h.
#include "core/gl/gl_context.h"

#include <cstdio>
#include <cstring>
#include <vector>

#include "core/gl/gl_api.h"

namespace sylva {

namespace {

std::string egl_error_name(EGLint code) {
  switch (code) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: {
      char buffer[32];
      std::snprintf(buffer, sizeof buffer, "EGL error 0x%04x", static_cast<unsigned>(code));
      return buffer;
    }
  }
}

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  const size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

#ifndef NDEBUG
void APIENTRY print_debug_message(GLenum source, GLenum type, GLuint, GLenum severity, GLsizei,
                                    const GLchar* message, const void*) {
  // Shader compiler messages reach the caller through build_gl_program's logs.
  if (severity == GL_DEBUG_SEVERITY_NOTIFICATION || source == GL_DEBUG_SOURCE_SHADER_COMPILER) return;
  std::fprintf(stderr, "sylva: GL debug (%s): %s\n", type == GL_DEBUG_TYPE_ERROR ? "error" : "message", message);
}
#endif

// A display to try, and what to call it in messages.
struct Candidate {
  EGLDisplay display;
  std::string name;
  bool software;
};

// Tries one display: initialise, bind OpenGL, create a 4.5 core context, make it current
// without a surface, check the version. Returns the context (and its config, or
// EGL_NO_CONFIG_KHR, in *config_out) or sets *why.
EGLContext try_display(const Candidate& c, EGLConfig* config_out, std::string* why) {
  EGLint major = 0, minor = 0;
  if (c.display == EGL_NO_DISPLAY) {
    *why = "no display";
    return EGL_NO_CONTEXT;
  }
  if (!eglInitialize(c.display, &major, &minor)) {
    *why = "eglInitialize failed (" + egl_error_name(eglGetError()) + ")";
    return EGL_NO_CONTEXT;
  }
  const char* extensions = eglQueryString(c.display, EGL_EXTENSIONS);
  if (!has_extension(extensions, "EGL_KHR_surfaceless_context")) {
    *why = "no EGL_KHR_surfaceless_context";
    return EGL_NO_CONTEXT;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    *why = "no desktop OpenGL (eglBindAPI: " + egl_error_name(eglGetError()) + ")";
    return EGL_NO_CONTEXT;
  }
  EGLConfig config = nullptr;  // EGL_NO_CONFIG_KHR
  if (!has_extension(extensions, "EGL_KHR_no_config_context")) {
    const EGLint config_attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(c.display, config_attributes, &config, 1, &count) || count < 1) {
      *why = "no EGL config for OpenGL";
      return EGL_NO_CONTEXT;
    }
  }
  std::vector<EGLint> attributes = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT};
#ifndef NDEBUG
  attributes.insert(attributes.end(), {EGL_CONTEXT_OPENGL_DEBUG, EGL_TRUE});
#endif
  attributes.push_back(EGL_NONE);
  EGLContext context = eglCreateContext(c.display, config, EGL_NO_CONTEXT, attributes.data());
  if (context == EGL_NO_CONTEXT) {
    *why = "no OpenGL 4.5 core context (eglCreateContext: " + egl_error_name(eglGetError()) + ")";
    return EGL_NO_CONTEXT;
  }
  if (!eglMakeCurrent(c.display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    *why = "eglMakeCurrent without a surface failed (" + egl_error_name(eglGetError()) + ")";
    eglDestroyContext(c.display, context);
    return EGL_NO_CONTEXT;
  }
  GLint gl_major = 0, gl_minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &gl_major);
  glGetIntegerv(GL_MINOR_VERSION, &gl_minor);
  if (gl_major * 10 + gl_minor < 45) {
    *why = "OpenGL " + std::to_string(gl_major) + "." + std::to_string(gl_minor) + " < 4.5";
    eglMakeCurrent(c.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(c.display, context);
    return EGL_NO_CONTEXT;
  }
  *config_out = config;
  return context;
}

std::string gl_string(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? reinterpret_cast<const char*>(s) : "";
}

}  // namespace

bool is_software_renderer(std::string_view renderer) {
  return renderer.find("llvmpipe") != std::string_view::npos || renderer.find("softpipe") != std::string_view::npos ||
         renderer.find("swrast") != std::string_view::npos;
}

std::string GlContextInfo::describe() const {
  return renderer + ", OpenGL " + version + ", " + platform + (software ? " (software rasteriser)" : "");
}

GlContextResult create_headless_gl_context() {
  GlContextResult result;
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!client) {
    result.error = "EGL has no client extensions (" + egl_error_name(eglGetError()) +
                   "); is an EGL vendor library (libegl-mesa0 or the GPU driver's) installed?";
    return result;
  }
  auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  std::vector<Candidate> hardware, software;
  if (get_platform_display && has_extension(client, "EGL_EXT_platform_device")) {
    auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto query_device_string =
        reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    EGLint count = 0;
    if (query_devices && query_device_string && query_devices(0, nullptr, &count) && count > 0) {
      std::vector<EGLDeviceEXT> devices(static_cast<size_t>(count));
      query_devices(count, devices.data(), &count);
      for (EGLint i = 0; i < count; ++i) {
        const bool is_software = has_extension(query_device_string(devices[i], EGL_EXTENSIONS),
                                               "EGL_MESA_device_software");
        Candidate c{get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr),
                    "EGL device " + std::to_string(i) + (is_software ? " (software)" : " (hardware)"), is_software};
        (is_software ? software : hardware).push_back(c);
      }
    }
  }
  std::vector<Candidate> candidates = hardware;
  if (get_platform_display && has_extension(client, "EGL_MESA_platform_surfaceless"))
    candidates.push_back({get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr),
                          "EGL surfaceless (Mesa)", true});
  candidates.insert(candidates.end(), software.begin(), software.end());
  candidates.push_back({eglGetDisplay(EGL_DEFAULT_DISPLAY), "EGL default display", false});

  std::string reasons;
  for (const Candidate& c : candidates) {
    std::string why;
    EGLConfig config = nullptr;
    EGLContext context = try_display(c, &config, &why);
    if (context == EGL_NO_CONTEXT) {
      reasons += (reasons.empty() ? "" : "; ") + c.name + ": " + why;
      continue;
    }
    result.context.reset(new GlContext());
    result.context->display_ = c.display;
    result.context->context_ = context;
    result.context->config_ = config;
    GlContextInfo& info = result.context->info_;
    info.platform = c.name;
    info.vendor = gl_string(GL_VENDOR);
    info.renderer = gl_string(GL_RENDERER);
    info.version = gl_string(GL_VERSION);
    info.software = is_software_renderer(info.renderer);
#ifndef NDEBUG
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(print_debug_message, nullptr);
#endif
    return result;
  }
  result.error = "no OpenGL 4.5 core context through EGL: " + reasons;
  return result;
}

GlContext::~GlContext() {
  auto display = static_cast<EGLDisplay>(display_);
  if (eglGetCurrentContext() == static_cast<EGLContext>(context_))
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display, static_cast<EGLContext>(context_));
  eglReleaseThread();
}

void GlContext::make_current() {
  if (!eglMakeCurrent(static_cast<EGLDisplay>(display_), EGL_NO_SURFACE, EGL_NO_SURFACE,
                      static_cast<EGLContext>(context_)))
    throw GlError("eglMakeCurrent failed (" + egl_error_name(eglGetError()) + ")");
}

void GlContext::make_current(const GlPbuffer& surface) {
  auto egl_surface = static_cast<EGLSurface>(surface.surface_);
  if (!eglMakeCurrent(static_cast<EGLDisplay>(display_), egl_surface, egl_surface, static_cast<EGLContext>(context_)))
    throw GlError("eglMakeCurrent with a pbuffer failed (" + egl_error_name(eglGetError()) + ")");
}

GlPbufferResult GlContext::create_pbuffer(uint32_t width, uint32_t height) const {
  GlPbufferResult result;
  auto display = static_cast<EGLDisplay>(display_);
  EGLConfig config = static_cast<EGLConfig>(config_);
  if (!config) {  // a context without a config takes any surface's: choose an RGBA8 one
    const EGLint attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                 EGL_RED_SIZE,     8,               EGL_GREEN_SIZE,      8,
                                 EGL_BLUE_SIZE,    8,               EGL_ALPHA_SIZE,      8,
                                 EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display, attributes, &config, 1, &count) || count < 1) {
      result.error = "no RGBA8 pbuffer config for OpenGL on this display";
      return result;
    }
  }
  const EGLint attributes[] = {EGL_WIDTH, static_cast<EGLint>(width), EGL_HEIGHT, static_cast<EGLint>(height),
                               EGL_NONE};
  EGLSurface surface = eglCreatePbufferSurface(display, config, attributes);
  if (surface == EGL_NO_SURFACE) {
    result.error = "eglCreatePbufferSurface failed (" + egl_error_name(eglGetError()) + ")";
    return result;
  }
  result.pbuffer.reset(new GlPbuffer());
  result.pbuffer->display_ = display;
  result.pbuffer->surface_ = surface;
  result.pbuffer->width_ = width;
  result.pbuffer->height_ = height;
  return result;
}

GlPbuffer::~GlPbuffer() {
  eglDestroySurface(static_cast<EGLDisplay>(display_), static_cast<EGLSurface>(surface_));
}

}  // namespace sylva
