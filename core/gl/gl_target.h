// gl_target.h — where GlRenderer (render_gl.h) puts a frame's picture: a framebuffer the
// caller owns, or the default framebuffer of the caller's window; and a texture-backed
// framebuffer the caller can have made for that (the studio's image panel shows its
// texture with ImGui::Image).
//
// The present pass writes the frame's beauty (the accumulated shade passes ÷ spp, opaque)
// into colour attachment 0 of the target, one texel per pixel, rows bottom-up as GL's
// (ImGui::Image shows it upright with uv0 = (0, 1), uv1 = (1, 0)). Linear: the values
// GlRenderer::read_back returns, bit for bit where the target stores 32-bit floats;
// sRGB: encoded for display (core/util/color.h), for 8-bit targets and windows.
//
// Preconditions: as gl_objects.h (the renderer's context current on the calling thread);
// the target's size is the frame's (Scene::width × Scene::height) when drawn into.
#pragma once

#include <cstdint>

#include "core/gl/gl_objects.h"

namespace sylva {

enum class GlTargetEncoding : uint8_t {
  linear,  // linear radiance, as read_back returns it
  srgb,    // IEC 61966-2-1 encoded, clamped to [0, 1]: what a display shows as is
};

struct GlTarget {
  uint32_t framebuffer = 0;  // a complete framebuffer object; 0: the default framebuffer of the
                             // surface current on the context (a window's back buffer)
  uint32_t width = 0, height = 0;  // pixels: must equal the frame's size
  GlTargetEncoding encoding = GlTargetEncoding::linear;
};

// A texture and a framebuffer drawing into it, at one size; made and resized on the
// renderer's context. Format rgba32f keeps read_back's values exactly; rgba8 holds display
// values (target() encodes sRGB).
class GlTextureTarget {
 public:
  enum class Format : uint8_t { rgba32f, rgba8 };
  // Throws GlError beyond the driver's largest target.
  GlTextureTarget(uint32_t width, uint32_t height, Format format = Format::rgba32f);

  // Reallocates the texture for a new size; false (nothing done) when the size is the same.
  bool resize(uint32_t width, uint32_t height);

  uint32_t texture() const { return texture_.id(); }  // GL_TEXTURE_2D, one level
  uint32_t framebuffer() const { return framebuffer_.id(); }
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  Format format() const { return format_; }
  // This target for GlRenderer::draw: linear for rgba32f, sRGB for rgba8.
  GlTarget target() const;

 private:
  void allocate();
  Format format_;
  uint32_t width_ = 0, height_ = 0;
  GlTexture texture_;
  GlFramebuffer framebuffer_;
};

}  // namespace sylva
