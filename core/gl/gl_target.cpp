// gl_target.cpp — see gl_target.h.
#include "core/gl/gl_target.h"

#include <string>

#include "core/gl/gl_api.h"
#include "core/gl/gl_context.h"

namespace sylva {

GlTextureTarget::GlTextureTarget(uint32_t width, uint32_t height, Format format)
    : format_(format), width_(width), height_(height) {
  allocate();
}

bool GlTextureTarget::resize(uint32_t width, uint32_t height) {
  if (width == width_ && height == height_) return false;
  width_ = width;
  height_ = height;
  allocate();
  return true;
}

void GlTextureTarget::allocate() {
  const uint32_t max_size = max_gl_target_size();
  if (width_ == 0 || height_ == 0 || width_ > max_size || height_ > max_size)
    throw GlError("target " + std::to_string(width_) + "x" + std::to_string(height_) +
                  " is empty or exceeds the driver's largest (" + std::to_string(max_size) + " pixels a side)");
  texture_ = make_gl_texture_2d(format_ == Format::rgba32f ? GL_RGBA32F : GL_RGBA8, width_, height_);
  glTextureParameteri(texture_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(texture_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  framebuffer_ = make_gl_framebuffer();
  glNamedFramebufferTexture(framebuffer_.id(), GL_COLOR_ATTACHMENT0, texture_.id(), 0);
  check_gl_framebuffer(framebuffer_.id(), "texture target");
  check_gl("texture target");
}

GlTarget GlTextureTarget::target() const {
  return {framebuffer_.id(), width_, height_,
          format_ == Format::rgba32f ? GlTargetEncoding::linear : GlTargetEncoding::srgb};
}

}  // namespace sylva
