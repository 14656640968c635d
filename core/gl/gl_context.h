// gl_context.h — a window-less OpenGL 4.5 core context through EGL, for `sylva render
// --backend gl` and the GL tests: no X server, no surface; rendering goes to framebuffer
// objects (render_gl.h).
//
// Which display: EGL devices that are hardware GPUs first (EGL_EXT_platform_device; on an
// NVIDIA machine that is what works, and Mesa's surfaceless platform would silently give
// llvmpipe there), then Mesa's surfaceless platform (EGL_MESA_platform_surfaceless: llvmpipe
// on a CPU-only machine), then software devices, then EGL_DEFAULT_DISPLAY. The first
// display that gives an OpenGL 4.5 core context current without a surface wins; when
// none does, `error` says what each one answered.
//
// Debug builds (no NDEBUG) ask for a debug context and print GL debug messages above
// notification severity to stderr.
//
// Displays are initialised once per process and never terminated (EGL displays are
// process-wide; terminating one would pull it from under another context on it).
//
// A pbuffer (GlPbuffer) gives the context a default framebuffer without a window system:
// the tests draw through GlRenderer's window path (GlTarget framebuffer 0) into one.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

namespace sylva {

// A failure inside the GL backend (a shader that does not compile, an incomplete
// framebuffer, a size beyond the driver's limits), with a readable message.
struct GlError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Work stopped by RenderOptions::progress (core/util/progress.h) where there is no result
// to flag it on: a GlRenderer whose skinning was cancelled is never constructed. Not a
// failure: a front end that cancelled simply goes on with its newer request.
struct GlCancelled : std::runtime_error {
  GlCancelled() : std::runtime_error("cancelled") {}
};

// Whether GL_RENDERER `renderer` names a software rasteriser (llvmpipe, softpipe, swrast):
// timings are the CPU's, and the CPU ray caster is faster (docs/spec/cli.md --backend auto).
bool is_software_renderer(std::string_view renderer);

struct GlContextInfo {
  std::string platform;  // "EGL device 0 (hardware)", "EGL surfaceless (Mesa)", ...
  std::string vendor;    // GL_VENDOR
  std::string renderer;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string version;   // GL_VERSION
  bool software = false; // llvmpipe / softpipe / swrast: timings are the CPU's
  std::string describe() const;  // "llvmpipe (LLVM 15.0.6, 256 bits), OpenGL 4.5 ..., EGL surfaceless"
};

class GlContext;

// An off-screen EGL surface of the context's display: made current with the context
// (GlContext::make_current(pbuffer)), its colour buffer is the default framebuffer
// (RGBA8), as a window's back buffer is. Destroy it while another surface (or none) is
// current.
class GlPbuffer {
 public:
  ~GlPbuffer();
  GlPbuffer(const GlPbuffer&) = delete;
  GlPbuffer& operator=(const GlPbuffer&) = delete;
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }

 private:
  friend class GlContext;
  GlPbuffer() = default;
  void* display_ = nullptr;  // EGLDisplay
  void* surface_ = nullptr;  // EGLSurface
  uint32_t width_ = 0, height_ = 0;
};

struct GlPbufferResult {
  std::unique_ptr<GlPbuffer> pbuffer;  // null on failure
  std::string error;                   // why, when pbuffer is null
};

class GlContext {
 public:
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  const GlContextInfo& info() const { return info_; }
  // Makes the context current on the calling thread (creation already did, on its thread),
  // without a surface, or with `surface`'s default framebuffer (a pbuffer of this context's).
  void make_current();
  void make_current(const GlPbuffer& surface);

  // A width × height RGBA8 pbuffer on the context's display, or why there is none (the
  // display or the driver offers no pbuffer config for desktop OpenGL).
  GlPbufferResult create_pbuffer(uint32_t width, uint32_t height) const;

 private:
  friend struct GlContextResult create_headless_gl_context();
  GlContext() = default;
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  void* config_ = nullptr;   // EGLConfig the context was made with; null: EGL_NO_CONFIG_KHR
  GlContextInfo info_;
};

struct GlContextResult {
  std::unique_ptr<GlContext> context;  // null on failure
  std::string error;                   // why, when context is null
};

// Creates a headless OpenGL 4.5 core context and makes it current on this thread.
GlContextResult create_headless_gl_context();

}  // namespace sylva
