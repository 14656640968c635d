// crotch.glsl — the blended crotches' relief fade (CROTCH_FADE, with RELIEF): the GLSL twin of
// core/geometry/crotch.h's frustum_bound, crotch_field's k(p) and crotch_relief_fade, and of
// core/cpu/crotch_tracer.h's CrotchBalls::relief_fade, in float. relief.glsl scales the
// height field of a crotch's frusta by relief_fade, so their ribs sink into the fillet
// (which GL draws as a mesh, gl_mesh.h fillets_of) as they do on the CPU.
//
// Frames: a crotch's positions are relative to its origin_hi, a record's shape to the
// record's; a point is carried between them by the difference of the two origins (float
// origins of nearby records: the difference is exact). Tables: core/gl/gl_crotch_fade.h.

struct GpuCrotch {
  float origin_hi[3];
  float centre[3];
  float start[3];
  float direction[3];
  float radius;
  float k;
  float lateral_radius;
  float depth_step;
  uint parent_first;
  uint parent_count;
  uint lateral_first;
  uint lateral_count;
  uint depth_count;
  float depth[CROTCH_DEPTH_SAMPLES];
};
layout(std430, binding = CROTCHES_BINDING) readonly buffer Crotches { GpuCrotch crotches[]; };
layout(std430, binding = CROTCH_LISTS_BINDING) readonly buffer CrotchLists { uint crotch_lists[]; };

vec3 record_origin(uint record) {
  return vec3(segments[record].origin_hi[0], segments[record].origin_hi[1], segments[record].origin_hi[2]);
}

// crotch.h frustum_bound: the cone's apex-free distance and the two planes', the largest.
float frustum_bound_f(FrustumShapeF s, vec3 p) {
  vec3 w = p - s.base;
  float y = dot(w, s.axis);
  float rho = length(w - y * s.axis);
  float cone = (rho - (s.radius0 + s.slope * y)) / sqrt(1.0 + s.slope * s.slope);
  float lower = s.lower_offset - dot(s.lower_normal, p);
  float upper = dot(s.upper_normal, p) - s.upper_offset;
  return max(cone, max(lower, upper));
}

// The least bound at p (relative to `origin`) over the records lists[first, first + count).
float crotch_group_bound(uint first, uint count, vec3 p, vec3 origin) {
  float d = kInfinity;
  for (uint i = 0u; i < count; ++i) {
    uint record = crotch_lists[first + i];
    FrustumF f = unpack_gpu_segment(segments[record]);
    d = min(d, frustum_bound_f(f.shape, p + (origin - record_origin(record))));
  }
  return d;
}

// crotch.cpp depth_at: the parent's depth at the lateral's axis point s, linear between samples.
float crotch_depth_at(uint index, float s) {
  uint n = crotches[index].depth_count;
  if (n == 0u) return 0.0;
  float x = s / crotches[index].depth_step - 0.5;
  if (!(x > 0.0)) return crotches[index].depth[0];
  uint i = uint(x);
  if (i + 1u >= n) return crotches[index].depth[n - 1u];
  float f = x - float(i);
  return mix(crotches[index].depth[i], crotches[index].depth[i + 1u], f);
}

// crotch_relief_fade(crotch_field(crotch, p)) for p relative to the crotch's origin_hi.
float crotch_fade(uint index, vec3 p) {
  vec3 centre = vec3(crotches[index].centre[0], crotches[index].centre[1], crotches[index].centre[2]);
  float radius = crotches[index].radius;
  float x2 = dot(p - centre, p - centre) / (radius * radius);
  if (!(x2 < 1.0) || !(crotches[index].k > 0.0)) return 1.0;
  vec3 start = vec3(crotches[index].start[0], crotches[index].start[1], crotches[index].start[2]);
  vec3 direction = vec3(crotches[index].direction[0], crotches[index].direction[1], crotches[index].direction[2]);
  float ball = (1.0 - x2 * x2) * (1.0 - x2 * x2);
  float u = clamp((crotch_depth_at(index, dot(p - start, direction)) - crotches[index].lateral_radius) /
                      crotches[index].k, 0.0, 1.0);
  float k = crotches[index].k * ball * (1.0 - u * u * (3.0 - 2.0 * u));
  if (!(k > 0.0)) return 1.0;
  vec3 origin = vec3(crotches[index].origin_hi[0], crotches[index].origin_hi[1], crotches[index].origin_hi[2]);
  float parent = crotch_group_bound(crotches[index].parent_first, crotches[index].parent_count, p, origin);
  float lateral = crotch_group_bound(crotches[index].lateral_first, crotches[index].lateral_count, p, origin);
  float x = clamp((abs(parent - lateral) - k) / k, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

// CrotchBalls::relief_fade: the least fade at p (relative to `record`'s origin_hi) over the
// crotches that hold the record; 1 where none does.
float relief_fade(uint record, vec3 p) {
  uint list = crotch_lists[record];
  if (list == 0u) return 1.0;
  vec3 origin = record_origin(record);
  float fade = 1.0;
  uint n = crotch_lists[list];
  for (uint i = 0u; i < n; ++i) {
    uint index = crotch_lists[list + 1u + i];
    vec3 crotch_origin = vec3(crotches[index].origin_hi[0], crotches[index].origin_hi[1], crotches[index].origin_hi[2]);
    fade = min(fade, crotch_fade(index, p + (origin - crotch_origin)));
  }
  return fade;
}

// The difference step of the fade's gradient (CrotchBalls::fade_step_m): 10⁻² of the least
// k of the record's crotches, not the CPU's 10⁻³ — float's rounding of the bounds (~10⁻⁷ m)
// over a 10⁻⁴ m step would tilt the normal by ~10⁻³; the fade is smooth over k, so either
// step gives its gradient.
float relief_fade_step(uint record) {
  uint list = crotch_lists[record];
  if (list == 0u) return 1e-6;
  float k = kInfinity;
  uint n = crotch_lists[list];
  for (uint i = 0u; i < n; ++i) k = min(k, crotches[crotch_lists[list + 1u + i]].k);
  return 1e-2 * k;
}
