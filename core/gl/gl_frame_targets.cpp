// gl_frame_targets.cpp — see gl_frame_targets.h.
#include "core/gl/gl_frame_targets.h"

#include <string>

#include "core/gl/gl_api.h"
#include "core/gl/gl_context.h"

namespace sylva {

bool GlFrameTargets::resize(uint32_t w, uint32_t h, bool with_fog) {
  if (w == width && h == height && with_fog == fog) return false;
  const uint32_t max_size = max_gl_target_size();
  if (w > max_size || h > max_size)
    throw GlError("image " + std::to_string(w) + "x" + std::to_string(h) + " exceeds the driver's largest target (" +
                  std::to_string(max_size) + " pixels a side)");
  *this = GlFrameTargets();  // the old targets go first: never both sizes at once
  const GLenum formats[4] = {GL_RGBA32F, GL_RGBA32F, GL_RGBA32UI, GL_RGBA16F};
  gbuffer_fbo = make_gl_framebuffer();
  for (int i = 0; i < 4; ++i) {
    gbuffer[i] = make_gl_texture_2d(formats[i], w, h);
    // texelFetch only, but an integer texture with a filtering mode is incomplete.
    glTextureParameteri(gbuffer[i].id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(gbuffer[i].id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glNamedFramebufferTexture(gbuffer_fbo.id(), GL_COLOR_ATTACHMENT0 + i, gbuffer[i].id(), 0);
  }
  depth = make_gl_renderbuffer(GL_DEPTH_COMPONENT32F, w, h);
  glNamedFramebufferRenderbuffer(gbuffer_fbo.id(), GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth.id());
  const GLenum draw_buffers[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                                  GL_COLOR_ATTACHMENT3};
  glNamedFramebufferDrawBuffers(gbuffer_fbo.id(), 4, draw_buffers);
  check_gl_framebuffer(gbuffer_fbo.id(), "G-buffer");
  accumulation = make_gl_texture_2d(GL_RGBA32F, w, h);
  glTextureParameteri(accumulation.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(accumulation.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  accumulation_fbo = make_gl_framebuffer();
  glNamedFramebufferTexture(accumulation_fbo.id(), GL_COLOR_ATTACHMENT0, accumulation.id(), 0);
  check_gl_framebuffer(accumulation_fbo.id(), "accumulation");
  if (with_fog) {
    fog_aov = make_gl_texture_2d(GL_RGBA32F, w, h);
    glTextureParameteri(fog_aov.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(fog_aov.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    fog_fbo = make_gl_framebuffer();
    glNamedFramebufferTexture(fog_fbo.id(), GL_COLOR_ATTACHMENT0, accumulation.id(), 0);
    glNamedFramebufferTexture(fog_fbo.id(), GL_COLOR_ATTACHMENT1, fog_aov.id(), 0);
    check_gl_framebuffer(fog_fbo.id(), "fog");
  }
  fog = with_fog;
  check_gl("render targets");
  width = w;
  height = h;
  return true;
}

bool GlShadowMap::resize(uint32_t side) {
  if (side == texels) return false;
  *this = GlShadowMap();
  map = make_gl_texture_2d(GL_DEPTH_COMPONENT32F, side, side);
  glTextureParameteri(map.id(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTextureParameteri(map.id(), GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glTextureParameteri(map.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(map.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(map.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
  glTextureParameteri(map.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
  const float border[4] = {1, 1, 1, 1};
  glTextureParameterfv(map.id(), GL_TEXTURE_BORDER_COLOR, border);
  fbo = make_gl_framebuffer();
  glNamedFramebufferTexture(fbo.id(), GL_DEPTH_ATTACHMENT, map.id(), 0);
  glNamedFramebufferDrawBuffer(fbo.id(), GL_NONE);
  check_gl_framebuffer(fbo.id(), "shadow map");
  check_gl("shadow map");
  texels = side;
  return true;
}

}  // namespace sylva
