// shadow_cones.glsl — the shadow cones of core/light/shadow_cones.h on the GPU: their record
// (uploaded once per plants and sun by core/gl/gl_fog.cpp), the solid as a frustum shape,
// and a ray's interval through it, for the fog's cone pass (fog_cones.vert/frag.glsl).
//
// Each cone is an apex-free solid 0 <= s <= end, ρ <= radius0 + slope·s: exactly a conical
// frustum cut by two planes perpendicular to its axis (cone_local_shape), so the frusta's
// bounding pyramid (skin.glsl) and intersector (ray_frustum.glsl, the files before this
// one) draw it unchanged. Positions are relative to the cone set's origin (gl_fog.h), the
// eye sent as eye − origin from double.

struct GpuShadowCone {   // core/gl/bindings.h GpuShadowConeRecord (48 bytes)
  vec4 base_radius0;     // base (metres from the cone set's origin), r(0)
  vec4 axis_end;         // unit axis away from the sun, end_s (the solid's length)
  vec4 slope_plant;      // dr/ds, the occluder's plant index (as a float), 0, 0
};
layout(std430, binding = FOG_CONES_BINDING) readonly buffer FogCones { GpuShadowCone fog_cones[]; };

// The cone's solid as the intersector sees a frustum (cone_local_shape of shadow_cones.h,
// placed at its base): end planes perpendicular to the axis, both capped.
FrustumShapeF shadow_cone_shape(GpuShadowCone c) {
  FrustumShapeF s;
  s.base = c.base_radius0.xyz;
  s.axis = c.axis_end.xyz;
  s.length_m = c.axis_end.w;
  s.radius0 = c.base_radius0.w;
  s.slope = c.slope_plant.x;
  s.lower_normal = s.axis;
  s.lower_offset = dot(s.axis, s.base);
  s.upper_normal = s.axis;
  s.upper_offset = s.lower_offset + s.length_m;
  s.caps = 3u;
  return s;
}

// Whether `p` lies in the closed solid (cone_contains of shadow_cones.h).
bool shadow_cone_contains(FrustumShapeF s, vec3 p) {
  vec3 r = p - s.base;
  float y = dot(r, s.axis);
  if (y < 0.0 || y > s.length_m) return false;
  vec3 perp = r - y * s.axis;
  float radius = s.radius0 + s.slope * y;
  return radius >= 0.0 && dot(perp, perp) <= radius * radius;
}

// The part of `ray` (t in units of its direction, t >= 0) inside the solid, as
// (t_in, t_out); t_out <= t_in where it misses. The intersector finds the first boundary
// crossing after a t; from outside that is the entry and the next one the exit.
vec2 shadow_cone_interval(RayF ray, FrustumShapeF s) {
  FrustumHitF first = intersect_frustum_f(ray, s, 0.0, kInfinity);
  if (shadow_cone_contains(s, ray.origin)) return vec2(0.0, first.kind == kHitNone ? 0.0 : first.t);
  if (first.kind == kHitNone) return vec2(0.0);
  FrustumHitF second = intersect_frustum_f(ray, s, first.t, kInfinity);
  return vec2(first.t, second.kind == kHitNone ? first.t : second.t);
}

