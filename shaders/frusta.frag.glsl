// frusta.frag.glsl — ray casting one frustum per fragment (paper 000, sec. 2.5): the ray
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

flat in FrustumShapeF v_shape;
flat in uvec4 v_segment_info;
flat in vec3 v_frame_origin;

#ifdef GBUFFER_PASS
#ifndef EYE_INSIDE
layout(depth_less) out float gl_FragDepth;
#endif
layout(location = 0) out vec4 g_normal_distance;  // shading normal (toward the eye), distance
layout(location = 1) out vec4 g_geometric_u;      // geometric normal (toward the eye), u
layout(location = 2) out uvec4 g_ids;             // plant | material << 24, chain, segment, v_m bits
#endif
#ifdef SHADOW_PASS
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
  FrustumHitF hit = intersect_frustum_f(ray, fr.shape, 0.0, kInfinity);
  if (hit.kind == kHitNone) discard;

#ifdef SHADOW_PASS
  gl_FragDepth = max(hit.t / u_light_depth.y, gl_FragCoord.z);
#else
  float depth = u_near / (hit.t * dot(ray.direction, u_forward));
#ifdef EYE_INSIDE
  gl_FragDepth = depth;
#else
  gl_FragDepth = min(depth, gl_FragCoord.z);
#endif
  vec3 view = -ray.direction;
  vec3 n_geometric = hit.normal;
  vec3 n_shading = hit.kind == kHitSide ? surface_normal(fr, hit.y, hit.radial) : hit.normal;
  if (dot(n_geometric, view) < 0.0) n_geometric = -n_geometric;  // seen from inside
  if (dot(n_shading, view) < 0.0) n_shading = -n_shading;
  float u = 0.0, v_m = 0.0;
#ifdef WANT_UV
  SurfaceUV uv = surface_uv(fr, hit.y, hit.radial, u_twist_rad_per_m);
  u = uv.u;
  v_m = uv.v_m;
#endif
  uvec4 ids = segment_ids[v_segment_info.x];
  g_normal_distance = vec4(n_shading, hit.t * length(ray.direction));
  g_geometric_u = vec4(n_geometric, u);
  g_ids = uvec4(ids.x | (fr.material << 24), ids.y, ids.z, floatBitsToUint(v_m));
#endif
}
