// gl_views.h — the two views every geometry pass draws in (shaders/views.glsl), shared by
// the frusta (render_gl.cpp) and the meshes (gl_mesh.cpp) so that both fill one G-buffer and
// one shadow map alike, and read by the shade pass for its shadow lookups: the camera of one
// sample, and the sun's orthographic view of the shadow map. Each is the set of
// default-block uniforms the programs declare under these names, converted to float once
// here and set by name on a program (a program without one of them skips it; gl_program.h).
// bindings.h says why they are not a uniform block.
//
// Positions are never sent in world coordinates: the eye and the map's centre go as hi +
// lo floats (frusta_common.glsl "Frames"). Preconditions: as gl_program.h.
#pragma once

#include <cstdint>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/scene/render_common.h"

namespace sylva {

// A double position as two floats whose sum is it to ~2^-48 relative: what the shaders add
// back in float (frusta_common.glsl "Frames").
struct GlFloatSplit {
  glm::vec3 hi{0}, lo{0};  // hi = float(v), lo = float(v − hi)
};
GlFloatSplit split_to_floats(const glm::dvec3& v);

// views.glsl's GBUFFER_PASS uniforms (and shade.frag.glsl's camera).
struct GlCameraView {
  glm::vec3 eye_hi{0}, eye_lo{0};                          // u_eye_hi, u_eye_lo
  glm::vec3 right{1, 0, 0}, up{0, 1, 0}, forward{0, 0, -1};  // u_right, u_up, u_forward
  glm::vec2 half_size{1, 1};                                 // u_half_size
  glm::vec2 image_size{1, 1};                                // u_image_size, pixels
  glm::vec2 jitter{0.5f, 0.5f};                              // u_jitter: where in its pixel a sample looks
  float near = 1e-3f;                                        // u_near: reversed-Z near plane, metres
};

// The camera of `frame` (render_common.h) at `width` × `height` pixels with near plane `near`.
GlCameraView camera_view(const render_common::CameraFrame& frame, double near, uint32_t width, uint32_t height);

// views.glsl's SHADOW_PASS uniforms, frusta_common.glsl's u_map_size, and the map frame
// shade.frag.glsl looks shadows up in.
struct GlSunView {
  glm::vec3 light_hi{0}, light_lo{0};  // u_light_hi, u_light_lo: the map's centre c
  glm::vec3 e0{1, 0, 0}, e1{0, 0, 1};  // u_light_e0, u_light_e1: axis_frame(direction)
  glm::vec3 direction{0, 1, 0};        // u_light_dir: unit, toward the sun
  glm::vec4 rect{0, 0, 1, 1};          // u_light_rect: x_min, y_min, x_size, y_size (metres from c)
  glm::vec2 depth{0, 1};               // u_light_depth: s_near, s_range
  glm::vec2 map_size{1, 1};            // u_map_size: texels
};

void set_camera_uniforms(uint32_t program, const GlCameraView& view);
void set_jitter_uniform(uint32_t program, const glm::vec2& jitter);
void set_sun_view_uniforms(uint32_t program, const GlSunView& view);

}  // namespace sylva
