// fog.glsl — the GLSL twin of core/light/fog.h / fog.cpp: the medium of docs/spec/fog.md and its
// closed forms (density, Schlick's phase function, optical depth and transmittance along a
// segment and toward the sun, the single-scattering integrals over a lit segment and the
// inverse of their distribution), in float. The same names, the same arguments in the
// same order, the same branches in the same order: fog.cpp says what each step does and
// why, docs/fog.md derives the formulas; tests/gl/gl_fog_twin_test.cpp compares the two
// case by case, stiff cases included.
//
// What float forces (each a constant below, each tested):
//  - no expm1/log1p in GLSL: fog_expm1 (a series below |x| < 0.35, exp(x) − 1 above,
//    where the cancellation costs at most a factor 3.4) and fog_lnrel by the atanh series
//    (−ln(1 − x) = 2·atanh(x/(2 − x)), |x| < 0.5), so σ → 0 and horizontal rays stay
//    ordinary cases, as in double.
//  - the range: e^{−x} leaves float's normal range at x ≈ 87.3, so T = 0 beyond
//    kFogMaxDepth = 80 (e^{−80} ≈ 1.8e-35, normal); densities within e^{±60}; lengths
//    clamped to kFogFar = 1e30 (times any rate below 1e8 still finite); results below
//    1e-30 flushed to 0 (never a denormal: llvmpipe and GPUs flush them anyway, and a
//    flush here is the same on every device).
//  - heights: the C++ forms y − ground in double once per point. The renderer gives this
//    file heights already (ground = 0, the eye's height above the ground computed in
//    double on the CPU), so an eye and a ground at 10⁶ m lose nothing here either.
// Units: metres, 1/m; a ray is origin + t·direction with `direction` unit.

#ifndef kInfinity  // ray_frustum.glsl's or shading.glsl's, where one comes first
#define kInfinity uintBitsToFloat(0x7F800000u)  // +inf (a const initializer cannot call it)
#endif

const float kFogMaxDepth = 80.0;     // optical depths beyond: T = 0 exactly
const float kFogMaxExponent = 60.0;  // density exponents beyond ±60: 0 below, clamped above
const float kFogFar = 1e30;          // lengths and depths clamped here before they meet a rate
const float kFogSeriesBelow = 0.35;  // fog_expm1's series below this |x| (8 terms: < 1e-9 relative)
const float kFogLnrelSeriesBelow = 0.5;  // fog_lnrel's atanh series below this |x|
const float kFogMinSunY = 1e-30;     // a lower sun lights no fog (fog.cpp kMinSunY)
const float kFogFlushBelow = 1e-30;  // results below are 0
const float kFogInvFourPi = 0.0795774715459476679;  // 1/(4π)

// fog.h's FogMedium (fog_medium builds it on the CPU; render_gl.cpp sets it as uniforms).
struct FogMedium {
  float sigma_s;
  float sigma_a;
  float sigma_t;
  float albedo;
  float height_falloff;
  float ground;  // 0 in the renderer: heights are given above the ground (see above)
  float top;     // +inf: no ceiling
  float g;
  float schlick_k;
};

struct FogClip {
  float t0;
  float t1;
  bool empty;
};

struct FogSegment {
  float sun;
  float sky;
  float depth;
};

float fog_flush_tiny(float x) { return x < kFogFlushBelow ? 0.0 : x; }

// ---- Phase function -------------------------------------------------------------------

float fog_schlick_k(float g) { return 1.55 * g - 0.55 * g * g * g; }

float fog_phase_schlick(float k, float cos_theta) {
  float denominator = 1.0 - k * cos_theta;
  return (1.0 - k) * (1.0 + k) * kFogInvFourPi / (denominator * denominator);
}

// ---- Limit-safe elementary functions --------------------------------------------------

// (e^x − 1)/x by its series: 8 terms, the first omitted one below 1e-9 of it for |x| < 0.35.
float fog_exprel_series(float x) {
  return 1.0 + x * (1.0 / 2.0 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0 + x * (1.0 / 720.0 +
         x * (1.0 / 5040.0 + x * (1.0 / 40320.0)))))));
}

// std::expm1, which GLSL lacks: the series where exp(x) − 1 would cancel.
float fog_expm1(float x) { return abs(x) < kFogSeriesBelow ? x * fog_exprel_series(x) : exp(x) - 1.0; }

float fog_exprel(float x) {
  if (abs(x) < kFogSeriesBelow) return fog_exprel_series(x);
  float clamped = min(x, kFogMaxDepth);
  return fog_expm1(clamped) / clamped;
}

float fog_lnrel(float x) {
  if (x >= 1.0) return kInfinity;
  if (abs(x) < kFogLnrelSeriesBelow) {
    // −ln(1 − x) = 2·atanh(z), z = x/(2 − x): lnrel = 2/(2 − x)·(1 + w/3 + w²/5 + …), w = z² <= 1/9.
    float z = x / (2.0 - x);
    float w = z * z;
    return 2.0 / (2.0 - x) *
           (1.0 + w * (1.0 / 3.0 + w * (1.0 / 5.0 + w * (1.0 / 7.0 + w * (1.0 / 9.0 + w * (1.0 / 11.0 +
            w * (1.0 / 13.0 + w * (1.0 / 15.0))))))));
  }
  return -log(1.0 - x) / x;
}

float fog_exp_integral(float length, float rate) {
  float l = min(length, kFogFar);
  if (!(l > 0.0)) return 0.0;
  float x = rate * l;
  if (x < kFogSeriesBelow) return l * fog_exprel(-x);
  return -fog_expm1(-x) / rate;
}

float fog_transmittance_of_depth(float depth) { return depth > kFogMaxDepth ? 0.0 : exp(-depth); }

// ---- The medium along rays ------------------------------------------------------------

struct FogHeights {
  float origin;  // origin.y − ground
  float top;     // top − ground (+inf: no ceiling)
};

FogHeights fog_heights_of(FogMedium medium, float origin_y) {
  return FogHeights(origin_y - medium.ground, medium.top - medium.ground);
}

float fog_density_at_height(float height_falloff, float height) {
  float exponent = -height_falloff * height;
  if (exponent < -kFogMaxExponent) return 0.0;
  return exp(min(exponent, kFogMaxExponent));
}

float fog_height_at(FogHeights h, float direction_y, float t) { return h.origin + min(t, kFogFar) * direction_y; }

FogClip fog_clip_heights(FogHeights h, float direction_y, float t0, float t1) {
  FogClip clip = FogClip(t0, t1, false);
  float above = h.origin - h.top;
  if (direction_y > 0.0) {
    clip.t1 = min(t1, -above / direction_y);
  } else if (direction_y < 0.0) {
    clip.t0 = max(t0, -above / direction_y);
  } else if (above > 0.0) {
    clip.t1 = clip.t0;
  }
  clip.empty = !(clip.t1 > clip.t0);
  return clip;
}

float fog_clipped_optical_depth(FogMedium medium, FogHeights h, float direction_y, float a, float b) {
  float far_t = min(b, kFogFar);
  float near_t = min(a, far_t);
  float length_m = far_t - near_t;
  float t_low = direction_y >= 0.0 ? near_t : far_t;
  float sigma_low = medium.sigma_t * fog_density_at_height(medium.height_falloff, fog_height_at(h, direction_y, t_low));
  if (sigma_low == 0.0) return 0.0;
  return fog_flush_tiny(sigma_low * fog_exp_integral(length_m, medium.height_falloff * abs(direction_y)));
}

float fog_optical_depth_heights(FogMedium medium, FogHeights h, float direction_y, float t0, float t1) {
  FogClip clip = fog_clip_heights(h, direction_y, t0, t1);
  if (clip.empty) return 0.0;
  return fog_clipped_optical_depth(medium, h, direction_y, clip.t0, clip.t1);
}

float fog_sun_optical_depth_at(FogMedium medium, float height, float top_height, float sun_y) {
  return fog_optical_depth_heights(medium, FogHeights(height, top_height), sun_y, 0.0, kInfinity);
}

float fog_sample_exponential(float xi, float length_m, float rate) {
  float w = -fog_expm1(-rate * length_m);
  return min(length_m, xi * fog_exp_integral(length_m, rate) * fog_lnrel(xi * w));
}

float fog_sun_rate(float direction_y, float sun_y) { return (sun_y - direction_y) / sun_y; }

FogMedium fog_medium(float sigma_s, float sigma_a, float g, float height_falloff, float ground, float top) {
  FogMedium m;
  m.sigma_s = sigma_s;
  m.sigma_a = sigma_a;
  m.sigma_t = sigma_s + sigma_a;
  m.albedo = m.sigma_t > 0.0 ? sigma_s / m.sigma_t : 0.0;
  m.height_falloff = height_falloff;
  m.ground = ground;
  m.top = top;
  m.g = g;
  m.schlick_k = fog_schlick_k(g);
  return m;
}

float fog_density(FogMedium medium, float y) {
  if (y > medium.top) return 0.0;
  return fog_density_at_height(medium.height_falloff, y - medium.ground);
}

FogClip fog_clip_to_top(FogMedium medium, vec3 origin, vec3 direction, float t0, float t1) {
  return fog_clip_heights(fog_heights_of(medium, origin.y), direction.y, t0, t1);
}

float fog_optical_depth(FogMedium medium, vec3 origin, vec3 direction, float t0, float t1) {
  return fog_optical_depth_heights(medium, fog_heights_of(medium, origin.y), direction.y, t0, t1);
}

float fog_transmittance(FogMedium medium, vec3 origin, vec3 direction, float t0, float t1) {
  return fog_transmittance_of_depth(fog_optical_depth(medium, origin, direction, t0, t1));
}

float fog_sun_optical_depth(FogMedium medium, vec3 point, vec3 sun_direction) {
  FogHeights h = fog_heights_of(medium, point.y);
  return fog_sun_optical_depth_at(medium, h.origin, h.top, sun_direction.y);
}

float fog_sun_transmittance(FogMedium medium, vec3 point, vec3 sun_direction) {
  return fog_transmittance_of_depth(fog_sun_optical_depth(medium, point, sun_direction));
}

float fog_distance_at_depth(FogMedium medium, vec3 origin, vec3 direction, float t0, float depth) {
  if (!(depth > 0.0)) return t0;
  FogHeights h = fog_heights_of(medium, origin.y);
  float sigma0 = medium.sigma_t * fog_density_at_height(medium.height_falloff, fog_height_at(h, direction.y, t0));
  if (sigma0 == 0.0) return kInfinity;
  float per_sigma = depth / sigma0;
  float s = per_sigma * fog_lnrel(medium.height_falloff * direction.y * per_sigma);
  if (!(s < kFogFar)) return kInfinity;
  float t = t0 + s;
  if (direction.y > 0.0 && t > (h.top - h.origin) / direction.y) return kInfinity;
  return t;
}

// ---- Single scattering over a lit segment ---------------------------------------------

FogSegment fog_shadowed_segment(FogMedium medium, vec3 origin, vec3 direction, float t0, float t1, float depth_to_t0) {
  FogSegment out_segment = FogSegment(0.0, 0.0, 0.0);
  FogHeights h = fog_heights_of(medium, origin.y);
  FogClip clip = fog_clip_heights(h, direction.y, t0, t1);
  if (clip.empty) return out_segment;
  out_segment.depth = fog_clipped_optical_depth(medium, h, direction.y, clip.t0, clip.t1);
  out_segment.sky =
      fog_flush_tiny(medium.albedo * fog_transmittance_of_depth(depth_to_t0) * -fog_expm1(-out_segment.depth));
  return out_segment;
}

FogSegment fog_lit_segment(FogMedium medium, vec3 origin, vec3 direction, vec3 sun_direction, float t0, float t1,
                           float depth_to_t0) {
  FogSegment out_segment = fog_shadowed_segment(medium, origin, direction, t0, t1, depth_to_t0);
  if (out_segment.depth == 0.0 || !(sun_direction.y > kFogMinSunY) || medium.albedo == 0.0) return out_segment;
  FogHeights h = fog_heights_of(medium, origin.y);
  FogClip clip = fog_clip_heights(h, direction.y, t0, t1);
  float kappa = fog_sun_rate(direction.y, sun_direction.y);
  float anchor_t = kappa >= 0.0 ? clip.t0 : clip.t1;
  float anchor_depth = depth_to_t0 + (kappa >= 0.0 ? 0.0 : out_segment.depth) +
                       fog_sun_optical_depth_at(medium, fog_height_at(h, direction.y, anchor_t), h.top, sun_direction.y);
  out_segment.sun = fog_flush_tiny(medium.albedo * fog_transmittance_of_depth(anchor_depth) *
                                   fog_exp_integral(out_segment.depth, abs(kappa)));
  return out_segment;
}

float fog_sample_lit_segment(FogMedium medium, vec3 origin, vec3 direction, vec3 sun_direction, float t0, float t1,
                             float xi) {
  FogHeights h = fog_heights_of(medium, origin.y);
  FogClip clip = fog_clip_heights(h, direction.y, t0, t1);
  if (clip.empty || !(sun_direction.y > kFogMinSunY) || medium.albedo == 0.0) return t0;
  float depth = min(fog_clipped_optical_depth(medium, h, direction.y, clip.t0, clip.t1), kFogFar);
  if (depth == 0.0) return t0;
  float kappa = fog_sun_rate(direction.y, sun_direction.y);
  float tau = kappa >= 0.0 ? fog_sample_exponential(xi, depth, kappa)
                           : max(0.0, depth - fog_sample_exponential(1.0 - xi, depth, -kappa));
  float t = fog_distance_at_depth(medium, origin, direction, clip.t0, tau);
  return clamp(t, clip.t0, min(clip.t1, kFogFar));
}

// Not in fog.h: shading.glsl's ground_distance for the fog's own programs (fog.frag.glsl,
// fog_cones.frag.glsl), which include no shading.glsl: t where origin + t·direction meets
// the ground, +inf where it never does.
float fog_ground_distance(float above_ground, float direction_y) {
  return direction_y < 0.0 && above_ground > 0.0 ? -above_ground / direction_y : kInfinity;
}
