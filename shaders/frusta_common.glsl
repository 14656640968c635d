// frusta_common.glsl — what every stage of the frusta program shares: the buffers the
// renderer uploads once (core/gl/render_gl.cpp) and the per-pass uniforms (with views.glsl's).
//
// Frames: positions are never sent in world coordinates. Each record is relative to its
// origin_hi (skin.h), and the eye (or the shadow map's centre) is sent as hi + lo floats,
// so eye − origin_hi = (eye_hi − origin_hi) + eye_lo keeps float precision at 10^6 m.

// One GpuSegment per frustum (skin.h), uploaded once.
layout(std430, binding = SEGMENTS_BINDING) readonly buffer Segments { GpuSegment segments[]; };
// Per frustum: plant, chain, segment (knuckle: joint) index, 0.
layout(std430, binding = SEGMENT_IDS_BINDING) readonly buffer SegmentIds { uvec4 segment_ids[]; };
// EYE_INSIDE: the frusta whose bounding pyramid may contain the eye (this frame's list;
// INSTANCED: pairs of instance, record).
layout(std430, binding = SEGMENT_LIST_BINDING) readonly buffer SegmentList { uint segment_list[]; };

// INSTANCED: instances.glsl (before this file) holds the per-plant transforms.

uniform float u_twist_rad_per_m;  // SkinOptions::twist_rad_per_m (u of surface_uv, relief's u)

#ifdef GBUFFER_PASS
uniform vec3 u_ray_dx;        // ray differentials (texture.h): the next sample's direction
uniform vec3 u_ray_dy;        // to the right / below is direction + these (1 pixel / sqrt(spp))

// The primary ray through continuous pixel position (x, y), y downward from the top:
// render_cpu.cpp's frame_ray, relative to the eye.
vec3 camera_ray_direction(vec2 pixel) {
  float sx = (2.0 * pixel.x / u_image_size.x - 1.0) * u_half_size.x;
  float sy = (1.0 - 2.0 * pixel.y / u_image_size.y) * u_half_size.y;
  return u_forward + sx * u_right + sy * u_up;
}
#endif

#ifdef SHADOW_PASS
uniform vec2 u_map_size;      // texels
#endif
