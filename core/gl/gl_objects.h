// gl_objects.h — the GL backend's plumbing, in one place: RAII handles for the GL objects
// it creates (buffers, textures, renderbuffers, framebuffers, vertex arrays, programs,
// queries), the one error check (check_gl), immutable buffers and framebuffer checks.
//
// A handle owns one object name and deletes it when destroyed or reset; it moves, never
// copies. Names are plain uint32_t (GLuint) and kinds GLenum values as uint32_t, so this
// header includes no GL header: a window's code (the studio, with its own GL loader) can
// hold targets made here (gl_target.h).
//
// Preconditions: the GL context the object was made on is current on the calling thread
// whenever a handle is created, reset or destroyed (GL objects belong to a context, and
// deleting a name on another context deletes something else or nothing). Failures throw
// GlError (gl_context.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>

namespace sylva {

enum class GlObjectKind : uint8_t { buffer, texture, renderbuffer, framebuffer, vertex_array, program, query };

// Deletes object `name` of `kind` on the current context (glDelete*; 0 is ignored).
void delete_gl_object(GlObjectKind kind, uint32_t name);

template <GlObjectKind Kind>
class GlObject {
 public:
  GlObject() = default;
  explicit GlObject(uint32_t name) : name_(name) {}
  ~GlObject() { delete_gl_object(Kind, name_); }
  GlObject(GlObject&& other) noexcept : name_(std::exchange(other.name_, 0)) {}
  GlObject& operator=(GlObject&& other) noexcept {
    if (this != &other) reset(std::exchange(other.name_, 0));
    return *this;
  }
  GlObject(const GlObject&) = delete;
  GlObject& operator=(const GlObject&) = delete;

  uint32_t id() const { return name_; }
  explicit operator bool() const { return name_ != 0; }
  // Deletes the object held and takes `name` (0: none).
  void reset(uint32_t name = 0) {
    delete_gl_object(Kind, name_);
    name_ = name;
  }

 private:
  uint32_t name_ = 0;
};

using GlBuffer = GlObject<GlObjectKind::buffer>;
using GlTexture = GlObject<GlObjectKind::texture>;
using GlRenderbuffer = GlObject<GlObjectKind::renderbuffer>;
using GlFramebuffer = GlObject<GlObjectKind::framebuffer>;
using GlVertexArray = GlObject<GlObjectKind::vertex_array>;
using GlProgramObject = GlObject<GlObjectKind::program>;
using GlQuery = GlObject<GlObjectKind::query>;

// Throws GlError "WHERE: GL_INVALID_OPERATION" (the error's name) when glGetError reports
// one. Client-side: it does not wait for the GPU.
void check_gl(const char* where);

// An immutable-storage buffer (glNamedBufferStorage) holding `bytes` of `data`, with
// `storage_flags` (GL_DYNAMIC_STORAGE_BIT: may be rewritten by update_gl_buffer).
// Zero-sized storage is an error in GL: an empty buffer gets 64 unused zero bytes.
GlBuffer make_gl_buffer(const void* data, size_t bytes, uint32_t storage_flags = 0);
// Overwrites `bytes` at offset 0 of a buffer made with GL_DYNAMIC_STORAGE_BIT.
void update_gl_buffer(const GlBuffer& buffer, const void* data, size_t bytes);

GlTexture make_gl_texture_2d(uint32_t internal_format, uint32_t width, uint32_t height, int levels = 1);
GlRenderbuffer make_gl_renderbuffer(uint32_t internal_format, uint32_t width, uint32_t height);
GlFramebuffer make_gl_framebuffer();
GlVertexArray make_gl_vertex_array();
GlQuery make_gl_query(uint32_t target);

// Throws GlError "WHAT framebuffer incomplete (0x....)" unless `framebuffer` (0: the
// default framebuffer) is complete for drawing.
void check_gl_framebuffer(uint32_t framebuffer, const char* what);

// The largest width and height a render target may have on this driver (the smaller of
// GL_MAX_TEXTURE_SIZE and GL_MAX_RENDERBUFFER_SIZE).
uint32_t max_gl_target_size();

}  // namespace sylva
