// fog.frag.glsl — the fog resolve, one fragment per pixel: what the fog adds along the
// pixel's ray (docs/spec/fog.md, "What a pixel sees"), by core/scene/fog_integrator.cpp's equation with
// fog.glsl's closed forms (the file before fog_lists.glsl), added into the accumulated
// beauty — whose surface term the shade pass already multiplied by T(0, t_end) and whose
// sunlight by T_sun — and written, with T, to the fog AOV.
//
//   L_fog = ∫₀^t_end T(0,t)·σ_s(x(t))·[p(d·s)·E_sun·V(x(t))·T_sun(x(t)) + L_sky/2] dt
//
// The sky term and T are closed forms; the modes differ only in V (docs/fog.md, "On the
// GPU"), read from the shadow map (the frusta ray cast into it, orthographic along this
// sample's sun direction: what the shade pass reads too) where the CPU casts shadow rays:
//   FOG_BRUTE   the standard GPU baseline, a march of the shadow map: u_steps samples of
//               the unshadowed sunlit in-scatter W's distribution (fog_sample_lit_segment
//               at the shares (k + ξ_k)/steps, ξ_k jittered per pixel and sample), one
//               shadow-map lookup each: sun = W·ΣV/steps — the CPU's brute, the map for rays.
//   FOG_MEDIUM  the pixel's cone intervals (fog_lists.glsl), sorted and merged as they are
//               read: closed form over the parts outside them (V = 1 there), u_steps
//               samples of the distribution of the in-scatter inside them only, one
//               lookup each. The expectation is the CPU medium's (V = 1 outside the cones,
//               the shadow test inside), every sample spent where a shadow may be.
//   FOG_FAST    the same intervals, V = 0 inside them, closed form outside: no lookup.
//   FOG_MAP     the sun-space depth maps (fog_map.glsl), walked texel by texel along the
//               whole sunlit stretch: closed form over the parts in front of each map,
//               the maps' results averaged — the CPU's map mode, no lookup, no random number.
// A pixel whose list is incomplete (the node buffer was full, or its merged intervals
// exceed FOG_MAX_INTERVALS) is marched as FOG_BRUTE: unbiased, slower, counted.
// Without SUN (no sunlight reaches the fog) only the sky term and T are computed.
//
// The sunlit part stops where τ(0, t) reaches FOG_NEGLIGIBLE_DEPTH (fog_integrator.h's
// kFogNegligibleDepth), as on the CPU. Heights are above the ground (fog.glsl).

layout(binding = G_NORMAL_DISTANCE_UNIT) uniform sampler2D g_normal_distance;
#ifdef SUN
layout(binding = SHADOW_MAP_UNIT) uniform sampler2DShadow shadow_map;
#endif

uniform vec3 u_right;        // camera frame, as shade.frag.glsl
uniform vec3 u_up;
uniform vec3 u_forward;
uniform vec2 u_half_size;
uniform vec2 u_image_size;
uniform vec2 u_jitter;
uniform float u_eye_above_ground;  // eye.y − ground.height (double on the CPU)
uniform vec3 u_sky;                // L_sky
uniform vec4 u_fog_medium;         // sigma_s, sigma_a, g, height_falloff
uniform float u_fog_top;           // top − ground.height (+inf: none)
#ifdef SUN
uniform vec3 u_fog_sun_dir;        // unit, toward the sun's centre: phase and T_sun
uniform vec3 u_sun_radiance;       // E_sun
uniform uint u_steps;              // samples along the ray (FOG_BRUTE; FOG_MEDIUM inside the cones)
uniform uint u_seed;               // this sample's stream
uniform vec3 u_eye_rel_light;      // eye − the shadow map's centre (shade.frag.glsl's map frame)
uniform vec3 u_light_e0;
uniform vec3 u_light_e1;
uniform vec3 u_light_dir;          // the direction the map was drawn along (this sample's)
uniform vec4 u_light_rect;
uniform vec2 u_light_depth;
uniform float u_depth_bias;
#if defined(FOG_MEDIUM) || defined(FOG_FAST)
uniform bool u_cones;              // a cone set is uploaded (else every ray is marched whole)
#endif
#ifdef FOG_MAP
uniform vec3 u_eye_rel_maps;       // eye − the map set's origin (GlFogMaps::origin)
uniform uint u_map_count;          // maps uploaded, 1 .. FOG_MAX_MAPS
#endif
#endif

layout(location = 0) out vec4 colour;   // added into the accumulation (blending ONE, ONE)
layout(location = 1) out vec4 fog_aov;  // fog.R fog.G fog.B fog.T

vec3 camera_ray_direction(vec2 pixel) {
  float sx = (2.0 * pixel.x / u_image_size.x - 1.0) * u_half_size.x;
  float sy = (1.0 - 2.0 * pixel.y / u_image_size.y) * u_half_size.y;
  return u_forward + sx * u_right + sy * u_up;
}

#ifdef SUN
// A hash of 32 bits (Wellons' lowbias32): the per-pixel jitter, a stream per sample.
uint fog_hash(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
float fog_random(uint stream, uint k) { return float(fog_hash(stream ^ fog_hash(k)) >> 8) * (1.0 / 16777216.0); }

// V at x(t) = eye + t·d from the shadow map: 1 outside the map (nothing casts there), else
// the bilinear 2×2 comparison; beyond the farthest caster clamped to the empty map's 1.
float fog_visibility(vec3 d, float t) {
  vec3 q = u_eye_rel_light + t * d;
  vec2 uv = (vec2(dot(q, u_light_e0), dot(q, u_light_e1)) - u_light_rect.xy) / u_light_rect.zw;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 1.0;
  float depth = min((-dot(q, u_light_dir) - u_light_depth.x) / u_light_depth.y - u_depth_bias, 1.0);
  return texture(shadow_map, vec3(uv, depth));
}

// FOG_BRUTE over [a, b] (the CPU's sun_brute with the map for shadow rays).
float fog_sun_brute(FogMedium m, vec3 o, vec3 d, vec3 s, float a, float b, uint stream) {
  float weight = fog_lit_segment(m, o, d, s, a, b, 0.0).sun;
  if (!(weight > 0.0)) return 0.0;
  float visible = 0.0;
  for (uint k = 0u; k < u_steps; ++k) {
    float xi = (float(k) + fog_random(stream, k)) / float(u_steps);
    visible += fog_visibility(d, fog_sample_lit_segment(m, o, d, s, a, b, xi));
  }
  return weight * visible / float(u_steps);
}

#if defined(FOG_MEDIUM) || defined(FOG_FAST)
// [t0, t1] into the sorted, disjoint intervals (starts, ends)[0, count), merged with every
// one it overlaps or touches (shadow_cones.h sort_and_merge); false when a new interval
// would not fit.
bool fog_insert_interval(inout float starts[FOG_MAX_INTERVALS], inout float ends[FOG_MAX_INTERVALS],
                         inout int count, float t0, float t1) {
  int i = 0;
  while (i < count && ends[i] < t0) ++i;  // those wholly before
  int j = i;
  while (j < count && starts[j] <= t1) ++j;  // [i, j) overlap or touch it
  if (j > i) {
    starts[i] = min(starts[i], t0);
    ends[i] = max(ends[j - 1], t1);
    int removed = j - i - 1;
    for (int k = i + 1; k + removed < count; ++k) {
      starts[k] = starts[k + removed];
      ends[k] = ends[k + removed];
    }
    count -= removed;
    return true;
  }
  if (count == FOG_MAX_INTERVALS) return false;
  for (int k = count; k > i; --k) {
    starts[k] = starts[k - 1];
    ends[k] = ends[k - 1];
  }
  starts[i] = t0;
  ends[i] = t1;
  ++count;
  return true;
}
#endif
#endif

void main() {
  vec2 pixel = vec2(gl_FragCoord.x - 0.5 + u_jitter.x, u_image_size.y - gl_FragCoord.y - 0.5 + u_jitter.y);
  vec3 d = normalize(camera_ray_direction(pixel));
  float plant_m = texelFetch(g_normal_distance, ivec2(gl_FragCoord.xy), 0).w;
  float t_end = min(plant_m >= 0.0 ? plant_m : kInfinity, fog_ground_distance(u_eye_above_ground, d.y));
  FogMedium m = fog_medium(u_fog_medium.x, u_fog_medium.y, u_fog_medium.z, u_fog_medium.w, 0.0, u_fog_top);
  vec3 o = vec3(0.0, u_eye_above_ground, 0.0);
  // T(0, t_end) and the sky's share (L_sky/2, never shadowed): closed forms, to the end.
  float transmittance = fog_transmittance(m, o, d, 0.0, t_end);
  vec3 inscatter = (0.5 * fog_shadowed_segment(m, o, d, 0.0, t_end, 0.0).sky) * u_sky;
#ifdef SUN
  vec3 s = u_fog_sun_dir;
  FogClip clip = fog_clip_to_top(m, o, d, 0.0, t_end);
  float a = clip.t0;
  float b = min(min(clip.t1, fog_distance_at_depth(m, o, d, a, FOG_NEGLIGIBLE_DEPTH)), kFogFar);
  if (!clip.empty && b > a && s.y > 0.0 && m.albedo > 0.0) {
    uint pixel_index = uint(gl_FragCoord.y) * uint(u_image_size.x) + uint(gl_FragCoord.x);
    uint stream = fog_hash(pixel_index ^ fog_hash(u_seed));
    float sun = 0.0;
#if defined(FOG_MAP)
    uint texels = 0u;
    bool capped = false;
    for (uint k = 0u; k < uint(FOG_MAX_MAPS); ++k) {
      if (k >= u_map_count) break;
      sun += fog_map_sun(m, o, d, s, a, b, u_eye_rel_maps, k, texels, capped);
    }
    sun /= float(max(u_map_count, 1u));
#elif defined(FOG_MEDIUM) || defined(FOG_FAST)
    float starts[FOG_MAX_INTERVALS], ends[FOG_MAX_INTERVALS];
    for (int i = 0; i < FOG_MAX_INTERVALS; ++i) starts[i] = ends[i] = 0.0;  // (inout below)
    int count = 0;
    bool whole = !u_cones || fog_overflowed[pixel_index] != 0u;
    // The list's walk has a bound: on llvmpipe (Mesa 22.3) a loop whose trip count only the
    // data ends (while node != FOG_LIST_END) left every later loop of the shader after
    // one iteration — medium's march took 1 of u_steps samples (docs/gl-fog.md, "medium").
    // A list longer than the bound is marched whole, as an overflowed one.
    uint node = fog_heads[pixel_index];
    for (uint walked = 0u; walked <= FOG_MAX_LIST_NODES && !whole; ++walked) {
      if (node == FOG_LIST_END) break;
      if (walked == FOG_MAX_LIST_NODES) {
        whole = true;
        break;
      }
      FogNode n = fog_nodes[node];
      node = n.next;
      float t0 = max(n.t_in, a), t1 = min(n.t_out, b);
      if (t1 > t0) whole = !fog_insert_interval(starts, ends, count, t0, t1);
    }
    if (whole) {
      if (u_cones) atomicAdd(fog_overflow_pixels, 1u);
      sun = fog_sun_brute(m, o, d, s, a, b, stream);
    } else {
      // Outside the cones: lit, closed form; inside: each interval's unshadowed weight.
      float weights[FOG_MAX_INTERVALS];
      float depth = 0.0, t = a, cones_weight = 0.0;
      for (int i = 0; i < count; ++i) {
        if (starts[i] > t) {
          FogSegment lit = fog_lit_segment(m, o, d, s, t, starts[i], depth);
          sun += lit.sun;
          depth += lit.depth;
        }
        FogSegment inside = fog_lit_segment(m, o, d, s, starts[i], ends[i], depth);
        weights[i] = inside.sun;
        cones_weight += inside.sun;
        depth += inside.depth;
        t = ends[i];
      }
      if (b > t) sun += fog_lit_segment(m, o, d, s, t, b, depth).sun;
#ifdef FOG_MEDIUM
      if (cones_weight > 0.0) {
        // u_steps samples of the in-scatter's distribution over the cones' union: sample k
        // at the share (k + ξ_k)/steps, in the interval holding that share, at its share
        // within it. Every sample stands for cones_weight/steps.
        float visible = 0.0, below = 0.0;
        int i = 0;
        for (uint k = 0u; k < u_steps; ++k) {
          float share = (float(k) + fog_random(stream, k)) / float(u_steps) * cones_weight;
          while (i + 1 < count && (below + weights[i] <= share || weights[i] == 0.0)) below += weights[i++];
          float xi = clamp((share - below) / weights[i], 0.0, 1.0);
          visible += fog_visibility(d, fog_sample_lit_segment(m, o, d, s, starts[i], ends[i], xi));
        }
        sun += cones_weight * visible / float(u_steps);
      }
#endif
    }
#else
    sun = fog_sun_brute(m, o, d, s, a, b, stream);
#endif
    inscatter += (sun * fog_phase_schlick(m.schlick_k, dot(d, s))) * u_sun_radiance;
  }
#endif
  colour = vec4(inscatter, 0.0);
  fog_aov = vec4(inscatter, transmittance);
}
