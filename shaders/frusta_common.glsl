// frusta_common.glsl — what every stage of the frusta program shares: the buffers the
// renderer uploads once (core/render_gl.cpp) and the per-pass uniforms.
//
// Frames: positions are never sent in world coordinates. Each record is relative to its
// origin_hi (skin.h), and the eye (or the shadow map's centre) is sent as hi + lo floats,
// so eye − origin_hi = (eye_hi − origin_hi) + eye_lo keeps float precision at 10^6 m.

// One GpuSegment per frustum (skin.h), uploaded once.
layout(std430, binding = 0) readonly buffer Segments { GpuSegment segments[]; };
// Per frustum: plant, chain, segment (knuckle: joint) index, 0.
layout(std430, binding = 1) readonly buffer SegmentIds { uvec4 segment_ids[]; };
// EYE_INSIDE: the frusta whose bounding pyramid may contain the eye (this frame's list).
layout(std430, binding = 2) readonly buffer SegmentList { uint segment_list[]; };

#ifdef GBUFFER_PASS
uniform vec3 u_eye_hi;        // the eye, rounded to float
uniform vec3 u_eye_lo;        // eye − u_eye_hi
uniform vec3 u_right;         // camera frame (render_cpu.cpp's CameraFrame), unit
uniform vec3 u_up;
uniform vec3 u_forward;
uniform vec2 u_half_size;     // tan(fov_y/2)·aspect, tan(fov_y/2): image plane at distance 1
uniform vec2 u_image_size;    // width, height in pixels
uniform vec2 u_jitter;        // where in its pixel this pass samples ((0.5, 0.5): the centre)
uniform float u_near;         // reversed-Z infinite projection: depth = u_near / z_forward
uniform float u_twist_rad_per_m;  // SkinOptions::twist_rad_per_m (u of surface_uv)

// The primary ray through continuous pixel position (x, y), y downward from the top:
// render_cpu.cpp's frame_ray, relative to the eye.
vec3 camera_ray_direction(vec2 pixel) {
  float sx = (2.0 * pixel.x / u_image_size.x - 1.0) * u_half_size.x;
  float sy = (1.0 - 2.0 * pixel.y / u_image_size.y) * u_half_size.y;
  return u_forward + sx * u_right + sy * u_up;
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
uniform vec2 u_map_size;      // texels
#endif
