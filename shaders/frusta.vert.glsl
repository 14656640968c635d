// frusta.vert.glsl — vertex pulling (Bhagvat et al. 2009, sec. 2.6): vertex gl_VertexID draws corner
// kPyramidTriangles[gl_VertexID % 36] of the bounding pyramid of frustum gl_VertexID / 36
// (36: PYRAMID_VERTICES, bindings.glsl),
// built from its GpuSegment record (around the relief's shell where the plant has one); no
// vertex buffer. Every vertex of a frustum unpacks the same record and passes the same
// flat values on.

flat out FrustumShapeF v_shape;   // relative to the record's origin_hi
flat out uvec4 v_segment_info;    // frustum index, material | knuckle << 8, u_offset bits, v_lower_m bits
flat out vec3 v_frame_origin;     // the ray's origin frame: eye (light centre) − origin_hi
#ifdef INSTANCED
flat out uint v_instance;         // INSTANCED: the plant's transform (frusta_common.glsl)
#endif

void main() {
#if defined(EYE_INSIDE) && defined(INSTANCED)
  uint item = uint(gl_VertexID / PYRAMID_VERTICES);
  uint instance = segment_list[2u * item];
  uint segment = segment_list[2u * item + 1u];
#elif defined(EYE_INSIDE)
  uint segment = segment_list[gl_VertexID / PYRAMID_VERTICES];
#elif defined(INSTANCED)
  uint instance = u_instance_base + uint(gl_InstanceID);
  uint segment = uint(gl_VertexID / PYRAMID_VERTICES);  // gl_VertexID counts from the draw's first
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
#else
  vec3 frame_origin = (u_eye_hi - origin_hi) + u_eye_lo;
#endif
  vec3 corner_rel = corner - frame_origin;  // relative to the eye (light centre)
#ifdef INSTANCED
  GpuInstance inst = instances[instance];
  if (inst.own == 0u) {
    // The eye (light centre) in the plant's frame, relative to the record's origin_hi; the
    // corner taken to the world, relative to the eye.
#ifdef SHADOW_PASS
    vec3 view_rel = (u_light_hi - inst.position_hi) + (u_light_lo - inst.position_lo);
#else
    vec3 view_rel = (u_eye_hi - inst.position_hi) + (u_eye_lo - inst.position_lo);
#endif
    frame_origin = instance_unrotate(inst, view_rel) / inst.scale - origin_hi;
    corner_rel = inst.scale * instance_rotate(inst, corner + origin_hi) - view_rel;
  }
  v_instance = instance;
#endif
#ifdef SHADOW_PASS
  gl_Position = light_clip_position(corner_rel);
#else
  gl_Position = camera_clip_position(corner_rel);
#endif
  v_shape = fr.shape;
  v_segment_info = uvec4(segment, fr.material | (fr.knuckle ? 0x100u : 0u),
                         floatBitsToUint(fr.u_offset), floatBitsToUint(fr.v_lower_m));
  v_frame_origin = frame_origin;
}
