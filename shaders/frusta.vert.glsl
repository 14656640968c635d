// frusta.vert.glsl — vertex pulling (paper 000, sec. 2.6): vertex gl_VertexID draws corner
// kPyramidTriangles[gl_VertexID % 36] of the bounding pyramid of frustum gl_VertexID / 36
// (36: PYRAMID_VERTICES, bindings.glsl),
// built from its GpuSegment record (around the relief's shell where the plant has one); no
// vertex buffer. Every vertex of a frustum unpacks the same record and passes the same
// flat values on.

flat out FrustumShapeF v_shape;   // relative to the record's origin_hi
flat out uvec4 v_segment_info;    // frustum index, material | knuckle << 8, u_offset bits, v_lower_m bits
flat out vec3 v_frame_origin;     // the ray's origin frame: eye (light centre) − origin_hi

void main() {
#ifdef EYE_INSIDE
  uint segment = segment_list[gl_VertexID / PYRAMID_VERTICES];
#else
  uint segment = uint(gl_VertexID / PYRAMID_VERTICES);
#endif
  GpuSegment g = segments[segment];
  FrustumF fr = unpack_gpu_segment(g);
  vec3 origin_hi = vec3(g.origin_hi[0], g.origin_hi[1], g.origin_hi[2]);
  // The pyramid bounds what the fragment shader intersects: the frustum, or the outer
  // shell of its relief (relief.glsl; knuckles keep their exact surface, as on the CPU).
  FrustumShapeF bounded = fr.shape;
  float radius_max = max(g.radius0, g.radius1);
#ifdef RELIEF
  float relief_depth_m = plant_maps[segment_ids[segment].x].relief_depth_m;
  if (relief_depth_m > 0.0 && !fr.knuckle) {
    ShellDepths depths = relief_shell_depths(fr.shape, relief_depth_m, u_relief_max_depth_per_radius);
    bounded = relief_shell(fr.shape, relief_depth_m, u_relief_max_depth_per_radius);
    radius_max = max(g.radius0 + depths.lower_m, g.radius1 + depths.upper_m);
  }
#endif
  float size = fr.shape.length_m + radius_max;
  // Margins far above float rounding (~1e-7 of the size), far below a pixel.
  vec3 corner = bounding_pyramid_vertex(bounded, kPyramidTriangles[gl_VertexID % PYRAMID_VERTICES],
                                        1e-4 * radius_max + 1e-6 * size, 1e-4 * size);
#ifdef SHADOW_PASS
  vec3 frame_origin = (u_light_hi - origin_hi) + u_light_lo;
  gl_Position = light_clip_position(corner - frame_origin);
#else
  vec3 frame_origin = (u_eye_hi - origin_hi) + u_eye_lo;
  gl_Position = camera_clip_position(corner - frame_origin);
#endif
  v_shape = fr.shape;
  v_segment_info = uvec4(segment, fr.material | (fr.knuckle ? 0x100u : 0u),
                         floatBitsToUint(fr.u_offset), floatBitsToUint(fr.v_lower_m));
  v_frame_origin = frame_origin;
}
