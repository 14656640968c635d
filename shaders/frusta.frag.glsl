// frusta.frag.glsl — ray casting one frustum per fragment (Bhagvat et al. 2009, sec. 2.5): the ray
// through this fragment in the record's frame, intersect_frustum_f (ray_frustum.glsl), a
// discard on a miss, and the real hit depth in gl_FragDepth.
//
// GBUFFER_PASS writes what shading needs (deferred, shade.frag.glsl): normals turned
// toward the eye as render_cpu.cpp's shade() does, the Euclidean distance, ids, u/v_m.
// SHADOW_PASS writes only depth: an orthographic view along −u_light_dir.
//
// Conservative depth: the hit lies inside the pyramid, so behind the rasterised face.
// GBUFFER_PASS draws front faces with reversed Z (nearer is greater), so its depth only
// decreases (depth_less); SHADOW_PASS draws front faces with ordinary Z (depth_greater).
// The clamp keeps that promise where float rounds a cap hit (which lies on an end face)
// the wrong way. EYE_INSIDE draws back faces (a pyramid around the eye has no front face
// in view), whose depth bounds the hit from the other side: no layout there.
// NO_CONSERVATIVE_DEPTH leaves the layouts out (the same clamp, the same depth): what
// early depth testing is worth can be timed (GlRenderer::set_conservative_depth).
//
// RELIEF: frusta of a plant with a relief (bark.glsl's plant_maps[].relief_depth_m > 0)
// are intersected by relief.glsl's intersect_relief_f inside their shell (the pyramid
// bounds the shell, frusta.vert.glsl); knuckles keep their exact surface, as on the CPU.
// CROTCH_FADE (with RELIEF): the relief of a blended crotch's frusta fades into its fillet
// (crotch.glsl), as on the CPU.
// BARK: the albedo texture is looked up here, where the hit is known (bark.glsl), over
// the footprint of the ray differentials, into g_albedo (a = 1); a = 0 leaves the albedo
// to shade.frag.glsl (material table, bark colour).
// INSTANCED: a plant drawn through its transform (frusta_common.glsl) casts the ray in its
// skeleton's frame (origin and direction taken back, so t is the world ray's t) and turns
// the hit's normals, v_m and texture footprint back to the world (instance_tracer.h's
// world_hit on the CPU).

flat in FrustumShapeF v_shape;
flat in uvec4 v_segment_info;
flat in vec3 v_frame_origin;
#ifdef INSTANCED
flat in uint v_instance;
#endif

#ifdef GBUFFER_PASS
#if !defined(EYE_INSIDE) && !defined(NO_CONSERVATIVE_DEPTH)
layout(depth_less) out float gl_FragDepth;
#endif
layout(location = 0) out vec4 g_normal_distance;  // shading normal (toward the eye), distance
layout(location = 1) out vec4 g_geometric_u;      // geometric normal (toward the eye), u
layout(location = 2) out uvec4 g_ids;             // plant | material << 24, chain, segment, v_m bits
layout(location = 3) out vec4 g_albedo;           // linear albedo, a = 1 where decided here
#endif
#if defined(SHADOW_PASS) && !defined(NO_CONSERVATIVE_DEPTH)
layout(depth_greater) out float gl_FragDepth;
#endif

void main() {
  FrustumF fr = FrustumF(v_shape, uintBitsToFloat(v_segment_info.z), uintBitsToFloat(v_segment_info.w),
                         v_segment_info.y & 0xFFu, (v_segment_info.y & 0x100u) != 0u);
  RayF ray;
#ifdef SHADOW_PASS
  vec2 xy = u_light_rect.xy + gl_FragCoord.xy / u_map_size * u_light_rect.zw;
  ray.origin = v_frame_origin + xy.x * u_light_e0 + xy.y * u_light_e1 - u_light_depth.x * u_light_dir;
  ray.direction = -u_light_dir;
#else
  // gl_FragCoord is bottom-up at the pixel centre; the CPU's pixel position is top-down.
  vec2 pixel = vec2(gl_FragCoord.x - 0.5 + u_jitter.x, u_image_size.y - gl_FragCoord.y - 0.5 + u_jitter.y);
  ray.origin = v_frame_origin;
  ray.direction = camera_ray_direction(pixel);
#endif
  vec3 world_direction = ray.direction;
  uint plant = segment_ids[v_segment_info.x].x;
#ifdef INSTANCED
  GpuInstance inst = instances[v_instance];
  bool moved = inst.own == 0u;
  if (moved) {
#ifdef SHADOW_PASS
    ray.origin = v_frame_origin +
                 instance_unrotate(inst, xy.x * u_light_e0 + xy.y * u_light_e1 - u_light_depth.x * u_light_dir) / inst.scale;
#endif
    ray.direction = instance_unrotate(inst, ray.direction) / inst.scale;
    plant = inst.plant;
  }
#endif
#ifdef RELIEF
  ReliefMapF map = ReliefMapF(plant_maps[plant], plant_maps[plant].relief_depth_m, v_segment_info.x);
  bool relief = map.depth_m > 0.0 && !fr.knuckle && fr.material == 0u;  // bark: wood only
#ifdef SHADOW_PASS
  const bool describe = false;
#else
  const bool describe = true;
#endif
  ReliefHitF relief_hit = ReliefHitF(FrustumHitF(kHitNone, 0.0, vec3(0.0), 0.0, vec3(0.0)), 0.0, 0.0, vec3(0.0), false);
  FrustumHitF hit;
  if (relief) {
    relief_hit = intersect_relief_f(ray, fr, map, 0.0, kInfinity, describe);
    hit = relief_hit.hit;
  } else {
    hit = intersect_frustum_f(ray, fr.shape, 0.0, kInfinity);
  }
#else
  const bool relief = false;
  FrustumHitF hit = intersect_frustum_f(ray, fr.shape, 0.0, kInfinity);
#endif
  if (hit.kind == kHitNone) discard;

#ifdef SHADOW_PASS
  gl_FragDepth = max(hit.t / u_light_depth.y, gl_FragCoord.z);
#else
  float depth = u_near / (hit.t * dot(world_direction, u_forward));
#ifdef EYE_INSIDE
  gl_FragDepth = depth;
#else
  gl_FragDepth = min(depth, gl_FragCoord.z);
#endif
  vec3 view = -world_direction;
  vec3 n_geometric = hit.normal;
  vec3 n_shading = hit.kind == kHitSide ? surface_normal(fr, hit.y, hit.radial) : hit.normal;
  float u = 0.0, v_m = 0.0;
#if defined(WANT_UV) || defined(BARK)
  SurfaceUV uv = surface_uv(fr, hit.y, hit.radial, u_twist_rad_per_m);
  u = uv.u;
  v_m = uv.v_m;
#endif
#ifdef RELIEF
  if (relief) {
    n_shading = relief_hit.shading_normal;
    u = relief_hit.u;
    v_m = relief_hit.v_m;
  }
#endif
#ifdef INSTANCED
  if (moved) {
    v_m *= inst.scale;
    n_geometric = instance_rotate(inst, n_geometric);
    n_shading = instance_rotate(inst, n_shading);
  }
#endif
  vec4 albedo = vec4(0.0);
#ifdef BARK
  // describe_frustum_hit's / describe_relief_hit's tangents (frustum_tracer.cpp): around,
  // a full turn is the circumference at the hit's distance from the axis (the frustum's
  // radius, the relief's own); along, a metre of arc length is a metre of generator.
  vec3 position = hit.t * ray.direction;  // relative to the eye
  float around_m = fr.shape.radius0 + fr.shape.slope * hit.y;
  if (relief) {
    vec3 from_base = (ray.origin - fr.shape.base) + position;
    around_m = length(from_base - dot(from_base, fr.shape.axis) * fr.shape.axis);
  }
  vec3 dp_du = (2.0 * kPi * max(around_m, 0.0)) * cross(fr.shape.axis, hit.radial);
  vec3 dp_dv = normalize(fr.shape.axis + fr.shape.slope * hit.radial);
  vec3 ray_dx = u_ray_dx, ray_dy = u_ray_dy;
#ifdef INSTANCED
  if (moved) {
    ray_dx = instance_unrotate(inst, ray_dx) / inst.scale;
    ray_dy = instance_unrotate(inst, ray_dy) / inst.scale;
  }
#endif
  UvFootprint footprint = uv_footprint(position, hit.normal, dp_du, dp_dv, vec3(0.0), ray.direction + ray_dx,
                                       ray.direction + ray_dy);
#ifdef INSTANCED
  if (moved) {  // v_m in world metres: the plant's arc lengths are scale times the skeleton's
    footprint.dv_dx *= inst.scale;
    footprint.dv_dy *= inst.scale;
  }
#endif
  albedo = segment_albedo(plant, fr.material, u, v_m, footprint);  // the bark: wood only
#endif
  if (dot(n_geometric, view) < 0.0) n_geometric = -n_geometric;  // seen from inside
  if (dot(n_shading, view) < 0.0) n_shading = -n_shading;
  uvec4 ids = segment_ids[v_segment_info.x];
  g_normal_distance = vec4(n_shading, hit.t * length(world_direction));
  g_geometric_u = vec4(n_geometric, u);
  g_ids = uvec4(plant | (fr.material << PLANT_INDEX_BITS), ids.y, ids.z, floatBitsToUint(v_m));
  g_albedo = albedo;
#endif
}
