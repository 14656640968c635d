// gl_objects.cpp — see gl_objects.h.
#include "core/gl/gl_objects.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include "core/gl/gl_api.h"
#include "core/gl/gl_context.h"

namespace sylva {

void delete_gl_object(GlObjectKind kind, uint32_t name) {
  if (name == 0) return;
  switch (kind) {
    case GlObjectKind::buffer: glDeleteBuffers(1, &name); break;
    case GlObjectKind::texture: glDeleteTextures(1, &name); break;
    case GlObjectKind::renderbuffer: glDeleteRenderbuffers(1, &name); break;
    case GlObjectKind::framebuffer: glDeleteFramebuffers(1, &name); break;
    case GlObjectKind::vertex_array: glDeleteVertexArrays(1, &name); break;
    case GlObjectKind::program: glDeleteProgram(name); break;
    case GlObjectKind::query: glDeleteQueries(1, &name); break;
  }
}

void check_gl(const char* where) {
  const GLenum error = glGetError();
  if (error == GL_NO_ERROR) return;
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", error);
  const char* name = error == GL_OUT_OF_MEMORY                 ? "GL_OUT_OF_MEMORY"
                     : error == GL_INVALID_OPERATION           ? "GL_INVALID_OPERATION"
                     : error == GL_INVALID_VALUE               ? "GL_INVALID_VALUE"
                     : error == GL_INVALID_ENUM                ? "GL_INVALID_ENUM"
                     : error == GL_INVALID_FRAMEBUFFER_OPERATION ? "GL_INVALID_FRAMEBUFFER_OPERATION"
                                                               : code;
  throw GlError(std::string(where) + ": " + name);
}

GlBuffer make_gl_buffer(const void* data, size_t bytes, uint32_t storage_flags) {
  GLuint name = 0;
  glCreateBuffers(1, &name);
  GlBuffer buffer(name);
  static const uint8_t kPlaceholder[64] = {};
  glNamedBufferStorage(name, bytes ? static_cast<GLsizeiptr>(bytes) : 64, bytes ? data : kPlaceholder, storage_flags);
  return buffer;
}

void update_gl_buffer(const GlBuffer& buffer, const void* data, size_t bytes) {
  if (bytes) glNamedBufferSubData(buffer.id(), 0, static_cast<GLsizeiptr>(bytes), data);
}

GlTexture make_gl_texture_2d(uint32_t internal_format, uint32_t width, uint32_t height, int levels) {
  GLuint name = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &name);
  GlTexture texture(name);
  glTextureStorage2D(name, levels, internal_format, static_cast<GLsizei>(width), static_cast<GLsizei>(height));
  return texture;
}

GlRenderbuffer make_gl_renderbuffer(uint32_t internal_format, uint32_t width, uint32_t height) {
  GLuint name = 0;
  glCreateRenderbuffers(1, &name);
  GlRenderbuffer renderbuffer(name);
  glNamedRenderbufferStorage(name, internal_format, static_cast<GLsizei>(width), static_cast<GLsizei>(height));
  return renderbuffer;
}

GlFramebuffer make_gl_framebuffer() {
  GLuint name = 0;
  glCreateFramebuffers(1, &name);
  return GlFramebuffer(name);
}

GlVertexArray make_gl_vertex_array() {
  GLuint name = 0;
  glCreateVertexArrays(1, &name);
  return GlVertexArray(name);
}

GlQuery make_gl_query(uint32_t target) {
  GLuint name = 0;
  glCreateQueries(target, 1, &name);
  return GlQuery(name);
}

void check_gl_framebuffer(uint32_t framebuffer, const char* what) {
  const GLenum status = glCheckNamedFramebufferStatus(framebuffer, GL_DRAW_FRAMEBUFFER);
  if (status == GL_FRAMEBUFFER_COMPLETE) return;
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", status);
  const bool no_surface = framebuffer == 0 && status == GL_FRAMEBUFFER_UNDEFINED;
  throw GlError(std::string(what) + " framebuffer incomplete (" + code + ")" +
                (no_surface ? ": the context has no surface, so no default framebuffer" : ""));
}

uint32_t max_gl_target_size() {
  GLint max_texture = 0, max_renderbuffer = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture);
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_renderbuffer);
  return static_cast<uint32_t>(std::max(0, std::min(max_texture, max_renderbuffer)));
}

}  // namespace sylva
