// gl_frame_targets.h — GlRenderer's own render targets (render_gl.cpp): the G-buffer and the
// accumulated beauty at the frame's size, and the shadow map at its own. Each is
// reallocated only when its size changes, so a new camera or sun redraws into the same
// targets and a resize reallocates these alone (never the plants' buffers).
//
// Formats (what shade.frag.glsl reads, what read_back returns; bench gpu's memory column):
//   G-buffer  0 RGBA32F  shading normal toward the eye, distance (−1: no hit)
//             1 RGBA32F  geometric normal toward the eye, u
//             2 RGBA32UI plant | material << 24, chain, segment, v_m bits
//             3 RGBA16F  albedo decided by the geometry pass (a = 1), else 0
//             depth DEPTH_COMPONENT32F (reversed Z)
//   accumulation RGBA32F: the sum of the shade (and fog) passes
//   fog        RGBA32F  fog.R fog.G fog.B fog.T (a scene with fog only); the fog pass draws
//              into fog_fbo: attachment 0 the accumulation (its in-scatter added), 1 this
//   shadow map DEPTH_COMPONENT32F, compared (sampler2DShadow) bilinearly, border 1
// Preconditions: as gl_objects.h. Failures throw GlError.
#pragma once

#include <cstdint>

#include "core/gl/gl_objects.h"

namespace sylva {

struct GlFrameTargets {
  static constexpr uint64_t kBytesPerPixel = 16 + 16 + 16 + 8 + 4 + 16;
  static constexpr uint64_t kFogBytesPerPixel = 16;

  uint32_t width = 0, height = 0;  // 0 × 0 until the first resize
  bool fog = false;                // the fog AOV target and fog_fbo exist
  GlTexture gbuffer[4];
  GlRenderbuffer depth;
  GlFramebuffer gbuffer_fbo;
  GlTexture accumulation;
  GlFramebuffer accumulation_fbo;
  GlTexture fog_aov;
  GlFramebuffer fog_fbo;

  // Allocates every target at w × h, the fog's with `with_fog`; false (nothing done) when
  // that is what is there already. Throws GlError beyond the driver's largest target.
  bool resize(uint32_t w, uint32_t h, bool with_fog = false);
  uint64_t bytes() const { return (kBytesPerPixel + (fog ? kFogBytesPerPixel : 0)) * width * height; }
};

struct GlShadowMap {
  uint32_t texels = 0;  // side; 0 until the first resize
  GlTexture map;
  GlFramebuffer fbo;

  // Allocates the map at texels × texels; false when that is the size already.
  bool resize(uint32_t side);
  uint64_t bytes() const { return uint64_t{4} * texels * texels; }
};

}  // namespace sylva
