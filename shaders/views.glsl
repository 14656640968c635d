// views.glsl — the two views every geometry pass draws into, shared by the frusta
// (frusta.vert.glsl) and the meshes (mesh.vert.glsl) so that both fill one G-buffer and
// one shadow map alike: the camera (GBUFFER_PASS, or CAMERA_VIEW for the fog's cone pass,
// which draws in the camera's view but is no G-buffer pass) and the sun's orthographic view
// (SHADOW_PASS), their uniforms, and the projection of a point given relative to the
// view's origin (eye or map centre; the caller forms that difference from hi + lo floats,
// frusta_common.glsl "Frames").

#if defined(GBUFFER_PASS) || defined(CAMERA_VIEW)
uniform vec3 u_eye_hi;        // the eye, rounded to float
uniform vec3 u_eye_lo;        // eye − u_eye_hi
uniform vec3 u_right;         // camera frame (render_common.h's CameraFrame), unit
uniform vec3 u_up;
uniform vec3 u_forward;
uniform vec2 u_half_size;     // tan(fov_y/2)·aspect, tan(fov_y/2): image plane at distance 1
uniform vec2 u_image_size;    // width, height in pixels
uniform vec2 u_jitter;        // where in its pixel this pass samples ((0.5, 0.5): the centre)
uniform float u_near;         // reversed-Z infinite projection: depth = u_near / z_forward

// Pinhole projection of p (relative to the eye), shifted so that the rasteriser samples
// each pixel where this pass's rays go (u_jitter), with reversed-Z infinite depth
// (z_clip = near, w = z): depth is u_near / z in (0, 1], 1 at the near plane, and float
// keeps its relative precision.
vec4 camera_clip_position(vec3 p) {
  float x = dot(p, u_right), y = dot(p, u_up), z = dot(p, u_forward);
  return vec4(x / u_half_size.x + (1.0 - 2.0 * u_jitter.x) / u_image_size.x * z,
              y / u_half_size.y + (2.0 * u_jitter.y - 1.0) / u_image_size.y * z, u_near, z);
}
#endif

#ifdef SHADOW_PASS
uniform vec3 u_light_hi;      // the shadow map's centre c, rounded to float
uniform vec3 u_light_lo;      // c − u_light_hi
uniform vec3 u_light_e0;      // map x: axis_frame(u_light_dir).e0
uniform vec3 u_light_e1;      // map y: axis_frame(u_light_dir).e1
uniform vec3 u_light_dir;     // unit, toward the sun; the map looks along −u_light_dir
uniform vec4 u_light_rect;    // x_min, y_min, x_size, y_size (metres, relative to c)
uniform vec2 u_light_depth;   // s_near, s_far − s_near: s = −dot(p − c, u_light_dir)

// Orthographic projection of p (relative to the map's centre c) along −u_light_dir: map
// depth (s − s_near) / s_range, the depth frusta.frag.glsl writes for a ray-cast hit.
vec4 light_clip_position(vec3 p) {
  float x = dot(p, u_light_e0), y = dot(p, u_light_e1), s = -dot(p, u_light_dir);
  return vec4(2.0 * (x - u_light_rect.x) / u_light_rect.z - 1.0, 2.0 * (y - u_light_rect.y) / u_light_rect.w - 1.0,
              (s - u_light_depth.x) / u_light_depth.y, 1.0);
}
#endif
