// gl_views.cpp — see gl_views.h.
#include "core/gl/gl_views.h"

#include "core/gl/gl_api.h"

namespace sylva {

namespace {
GLint location(uint32_t program, const char* name) { return glGetUniformLocation(program, name); }
void set3(uint32_t p, const char* name, const glm::vec3& v) { glProgramUniform3f(p, location(p, name), v.x, v.y, v.z); }
void set2(uint32_t p, const char* name, const glm::vec2& v) { glProgramUniform2f(p, location(p, name), v.x, v.y); }
}  // namespace

GlFloatSplit split_to_floats(const glm::dvec3& v) {
  GlFloatSplit s;
  for (int i = 0; i < 3; ++i) {
    // Rounded through a volatile float: GCC 12's SLP vectorizer (-O2) folds the round trip
    // double(float(x)) back to x when it vectorizes this, and lo comes out 0 — the map's
    // centre 10^6 m out lost its last 3 cm and the plants shadowed themselves.
    volatile float hi = static_cast<float>(v[i]);
    s.hi[i] = hi;
    s.lo[i] = static_cast<float>(v[i] - static_cast<double>(s.hi[i]));
  }
  return s;
}

GlCameraView camera_view(const render_common::CameraFrame& frame, double near, uint32_t width, uint32_t height) {
  GlCameraView v;
  const GlFloatSplit eye = split_to_floats(frame.eye);
  v.eye_hi = eye.hi;
  v.eye_lo = eye.lo;
  v.right = glm::vec3(frame.right);
  v.up = glm::vec3(frame.up);
  v.forward = glm::vec3(frame.forward);
  v.half_size = glm::vec2(static_cast<float>(frame.half_width), static_cast<float>(frame.half_height));
  v.image_size = glm::vec2(static_cast<float>(width), static_cast<float>(height));
  v.near = static_cast<float>(near);
  return v;
}

void set_camera_uniforms(uint32_t p, const GlCameraView& v) {
  set3(p, "u_eye_hi", v.eye_hi);
  set3(p, "u_eye_lo", v.eye_lo);
  set3(p, "u_right", v.right);
  set3(p, "u_up", v.up);
  set3(p, "u_forward", v.forward);
  set2(p, "u_half_size", v.half_size);
  set2(p, "u_image_size", v.image_size);
  set2(p, "u_jitter", v.jitter);
  glProgramUniform1f(p, location(p, "u_near"), v.near);
}

void set_jitter_uniform(uint32_t p, const glm::vec2& jitter) { set2(p, "u_jitter", jitter); }

void set_sun_view_uniforms(uint32_t p, const GlSunView& v) {
  set3(p, "u_light_hi", v.light_hi);
  set3(p, "u_light_lo", v.light_lo);
  set3(p, "u_light_e0", v.e0);
  set3(p, "u_light_e1", v.e1);
  set3(p, "u_light_dir", v.direction);
  glProgramUniform4f(p, location(p, "u_light_rect"), v.rect.x, v.rect.y, v.rect.z, v.rect.w);
  set2(p, "u_light_depth", v.depth);
  set2(p, "u_map_size", v.map_size);
}

}  // namespace sylva
