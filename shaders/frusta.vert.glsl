// frusta.vert.glsl — vertex pulling (paper 000, sec. 2.6): vertex gl_VertexID draws corner
// kPyramidTriangles[gl_VertexID % 36] of the bounding pyramid of frustum gl_VertexID / 36,
// built from its GpuSegment record; no vertex buffer. Every vertex of a frustum unpacks
// the same record and passes the same flat values on.

flat out FrustumShapeF v_shape;   // relative to the record's origin_hi
flat out uvec4 v_segment_info;    // frustum index, material | knuckle << 8, u_offset bits, v_lower_m bits
flat out vec3 v_frame_origin;     // the ray's origin frame: eye (light centre) − origin_hi

void main() {
#ifdef EYE_INSIDE
  uint segment = segment_list[gl_VertexID / 36];
#else
  uint segment = uint(gl_VertexID / 36);
#endif
  GpuSegment g = segments[segment];
  FrustumF fr = unpack_gpu_segment(g);
  vec3 origin_hi = vec3(g.origin_hi[0], g.origin_hi[1], g.origin_hi[2]);
  float radius_max = max(g.radius0, g.radius1);
  float size = fr.shape.length_m + radius_max;
  // Margins far above float rounding (~1e-7 of the size), far below a pixel.
  vec3 corner = bounding_pyramid_vertex(fr.shape, kPyramidTriangles[gl_VertexID % 36],
                                        1e-4 * radius_max + 1e-6 * size, 1e-4 * size);
#ifdef SHADOW_PASS
  vec3 frame_origin = (u_light_hi - origin_hi) + u_light_lo;
  vec3 p = corner - frame_origin;  // relative to the map's centre
  float x = dot(p, u_light_e0), y = dot(p, u_light_e1), s = -dot(p, u_light_dir);
  gl_Position = vec4(2.0 * (x - u_light_rect.x) / u_light_rect.z - 1.0,
                     2.0 * (y - u_light_rect.y) / u_light_rect.w - 1.0,
                     (s - u_light_depth.x) / u_light_depth.y, 1.0);
#else
  vec3 frame_origin = (u_eye_hi - origin_hi) + u_eye_lo;
  vec3 p = corner - frame_origin;  // relative to the eye
  float x = dot(p, u_right), y = dot(p, u_up), z = dot(p, u_forward);
  // Pinhole projection shifted so that the rasteriser samples each pixel where this pass's
  // rays go (u_jitter), with reversed-Z infinite depth (z_clip = near, w = z): depth is
  // u_near / z in (0, 1], 1 at the near plane, and float keeps its relative precision.
  gl_Position = vec4(x / u_half_size.x + (1.0 - 2.0 * u_jitter.x) / u_image_size.x * z,
                     y / u_half_size.y + (2.0 * u_jitter.y - 1.0) / u_image_size.y * z, u_near, z);
#endif
  v_shape = fr.shape;
  v_segment_info = uvec4(segment, fr.material | (fr.knuckle ? 0x100u : 0u),
                         floatBitsToUint(fr.u_offset), floatBitsToUint(fr.v_lower_m));
  v_frame_origin = frame_origin;
}
