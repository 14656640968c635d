// fog.cpp — the medium's closed forms (fog.h; docs/fog.md derives them). Each function is
// written as its GLSL twin will be: scalars, selects for the limit cases, the same order.
#include "core/light/fog.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sylva {

namespace {

// Where the series of exprel and lnrel take over from expm1/log1p: their first omitted
// terms (x⁴/120, x⁵/6) are below 1e-17 there, and the division is never 0/0.
constexpr double kSeriesBelow = 1e-4;
// A sun lower than this (s_y in radians above the horizon) lights no fog: from any point
// more than 1e-300·L below the top, the path to the top is longer than L/1e-300 — T_sun
// is 0 — and κ = (s_y − d_y)/s_y stays finite above it.
constexpr double kMinSunY = 1e-300;
// Results below this are returned as exactly 0: a subnormal would slow down every sum it
// later enters (Embree's docs recommend FTZ/DAZ for the same reason) and is meaningless here.
constexpr double kFlushBelow = 1e-300;

double flush_tiny(double x) { return x < kFlushBelow ? 0.0 : x; }

// Everything below works in heights above the ground, (y − ground) formed once per point,
// so an eye and a ground both at 10⁶ m lose nothing to cancellation: a height error of
// 1e-10 m (an ulp at 10⁶) would be a relative density error of h·1e-10.
struct Heights {
  double origin = 0;  // origin.y − ground
  double top = 0;     // top − ground (+inf: no ceiling)
};

Heights heights_of(const FogMedium& medium, double origin_y) {
  return {origin_y - medium.ground, medium.top - medium.ground};
}

// ρ at `height` metres above the ground, ignoring the top (the caller clipped the segment):
// exactly 0 below e^{−kFogMaxExponent}, clamped above e^{+kFogMaxExponent}.
double density_at_height(double height_falloff, double height) {
  const double exponent = -height_falloff * height;
  if (exponent < -kFogMaxExponent) return 0;
  return std::exp(std::min(exponent, kFogMaxExponent));
}

// Height above the ground of x(t); t is clamped to kFogFar (t = +inf: the far end).
double height_at(const Heights& h, double direction_y, double t) {
  return h.origin + std::min(t, kFogFar) * direction_y;
}

// fog_clip_to_top in heights.
FogClip clip_to_top(const Heights& h, double direction_y, double t0, double t1) {
  FogClip clip{t0, t1, false};
  const double above = h.origin - h.top;  // <= 0: the origin is in the fog's layer
  if (direction_y > 0) {
    clip.t1 = std::min(t1, -above / direction_y);
  } else if (direction_y < 0) {
    clip.t0 = std::max(t0, -above / direction_y);
  } else if (above > 0) {
    clip.t1 = clip.t0;  // horizontal above the top: never in the fog
  }
  clip.empty = !(clip.t1 > clip.t0);
  return clip;
}

// τ over [a, b] (a <= b, already clipped to the part below top; b may be +inf).
double clipped_optical_depth(const FogMedium& medium, const Heights& h, double direction_y, double a, double b) {
  const double far = std::min(b, kFogFar);
  const double near = std::min(a, far);
  const double length = far - near;
  // ρ is largest at the segment's lower end: going up it is the start, going down the end.
  const double t_low = direction_y >= 0 ? near : far;
  const double sigma_low = medium.sigma_t * density_at_height(medium.height_falloff, height_at(h, direction_y, t_low));
  if (sigma_low == 0) return 0;  // no fog here: 0, even for an unbounded segment
  return flush_tiny(sigma_low * fog_exp_integral(length, medium.height_falloff * std::abs(direction_y)));
}

// τ over [t0, t1] of the ray from height h.origin with vertical component direction_y.
double optical_depth(const FogMedium& medium, const Heights& h, double direction_y, double t0, double t1) {
  const FogClip clip = clip_to_top(h, direction_y, t0, t1);
  if (clip.empty) return 0;
  return clipped_optical_depth(medium, h, direction_y, clip.t0, clip.t1);
}

// fog_sun_optical_depth from a point `height` metres above the ground.
double sun_optical_depth(const FogMedium& medium, double height, double top_height, double sun_y) {
  return optical_depth(medium, Heights{height, top_height}, sun_y, 0, kFogInfinity);
}

// τ with density ∝ e^{−rate·τ} on [0, length] (rate >= 0, length in [0, kFogFar]) at
// cumulative share xi in [0, 1]: −ln(1 − xi·w)/rate with w = 1 − e^{−rate·length}, written
// as xi·exp_integral(length, rate)·lnrel(xi·w) so that rate → 0 gives xi·length and an
// unbounded rate·length gives −ln(1 − xi)/rate.
double sample_exponential(double xi, double length, double rate) {
  const double w = -std::expm1(-rate * length);
  return std::min(length, xi * fog_exp_integral(length, rate) * fog_lnrel(xi * w));
}

// The sun integral's rate κ = (s_y − d_y)/s_y (fog.h), finite for any s_y > 0.
// Precondition: sun_y > kMinSunY.
double sun_rate(double direction_y, double sun_y) { return (sun_y - direction_y) / sun_y; }

}  // namespace

FogMedium fog_medium(double sigma_s, double sigma_a, double g, double height_falloff, double ground, double top) {
  FogMedium m;
  m.sigma_s = sigma_s;
  m.sigma_a = sigma_a;
  m.sigma_t = sigma_s + sigma_a;
  m.albedo = m.sigma_t > 0 ? sigma_s / m.sigma_t : 0.0;
  m.height_falloff = height_falloff;
  m.ground = ground;
  m.top = top;
  m.g = g;
  m.schlick_k = fog_schlick_k(g);
  return m;
}

double fog_schlick_k(double g) { return 1.55 * g - 0.55 * g * g * g; }

double fog_phase_schlick(double k, double cos_theta) {
  const double denominator = 1 - k * cos_theta;
  // (1 − k)(1 + k) keeps 1 − k² accurate as |k| → 1.
  return (1 - k) * (1 + k) / (4 * std::numbers::pi * denominator * denominator);
}

double fog_exprel(double x) {
  if (std::abs(x) < kSeriesBelow) return 1 + x * (0.5 + x * (1.0 / 6 + x * (1.0 / 24)));
  const double clamped = std::min(x, kFogMaxDepth);
  return std::expm1(clamped) / clamped;
}

double fog_lnrel(double x) {
  if (x >= 1) return kFogInfinity;
  if (std::abs(x) < kSeriesBelow) return 1 + x * (0.5 + x * (1.0 / 3 + x * (0.25 + x * 0.2)));
  return -std::log1p(-x) / x;
}

double fog_exp_integral(double length, double rate) {
  const double l = std::min(length, kFogFar);
  if (!(l > 0)) return 0;  // also for an unbounded rate
  const double x = rate * l;  // may be +inf (then −expm1(−x)/rate = 1/rate); never NaN
  if (x < kSeriesBelow) return l * (1 - x * (0.5 - x * (1.0 / 6 - x * (1.0 / 24))));
  return -std::expm1(-x) / rate;
}

double fog_transmittance_of_depth(double depth) { return depth > kFogMaxDepth ? 0.0 : std::exp(-depth); }

double fog_density(const FogMedium& medium, double y) {
  if (y > medium.top) return 0;
  return density_at_height(medium.height_falloff, y - medium.ground);
}

FogClip fog_clip_to_top(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction, double t0,
                        double t1) {
  return clip_to_top(heights_of(medium, origin.y), direction.y, t0, t1);
}

double fog_optical_depth(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction, double t0,
                         double t1) {
  return optical_depth(medium, heights_of(medium, origin.y), direction.y, t0, t1);
}

double fog_transmittance(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction, double t0,
                         double t1) {
  return fog_transmittance_of_depth(fog_optical_depth(medium, origin, direction, t0, t1));
}

double fog_sun_optical_depth(const FogMedium& medium, const glm::dvec3& point, const glm::dvec3& sun_direction) {
  const Heights h = heights_of(medium, point.y);
  return sun_optical_depth(medium, h.origin, h.top, sun_direction.y);
}

double fog_sun_transmittance(const FogMedium& medium, const glm::dvec3& point, const glm::dvec3& sun_direction) {
  return fog_transmittance_of_depth(fog_sun_optical_depth(medium, point, sun_direction));
}

double fog_distance_at_depth(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                             double t0, double depth) {
  if (!(depth > 0)) return t0;
  const Heights h = heights_of(medium, origin.y);
  const double sigma0 = medium.sigma_t * density_at_height(medium.height_falloff, height_at(h, direction.y, t0));
  if (sigma0 == 0) return kFogInfinity;
  // τ(t0, t0 + s) = σ0·(1 − e^{−β s})/β with β = h·d_y, so s = −ln(1 − β τ/σ0)/β.
  const double per_sigma = depth / sigma0;
  const double s = per_sigma * fog_lnrel(medium.height_falloff * direction.y * per_sigma);
  if (!(s < kFogFar)) return kFogInfinity;  // climbing height fog runs out of depth
  const double t = t0 + s;
  // The ray leaves through the top first (t_top = +inf without a top).
  if (direction.y > 0 && t > (h.top - h.origin) / direction.y) return kFogInfinity;
  return t;
}

FogSegment fog_shadowed_segment(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                                double t0, double t1, double depth_to_t0) {
  FogSegment out;
  const Heights h = heights_of(medium, origin.y);
  const FogClip clip = clip_to_top(h, direction.y, t0, t1);
  if (clip.empty) return out;
  out.depth = clipped_optical_depth(medium, h, direction.y, clip.t0, clip.t1);
  // ∫ σ_s T(0,t) dt = albedo·T(0,t0)·(1 − T(t0,t1)) for any profile (σ_s = albedo·σ_t).
  out.sky = flush_tiny(medium.albedo * fog_transmittance_of_depth(depth_to_t0) * -std::expm1(-out.depth));
  return out;
}

FogSegment fog_lit_segment(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                           const glm::dvec3& sun_direction, double t0, double t1, double depth_to_t0) {
  FogSegment out = fog_shadowed_segment(medium, origin, direction, t0, t1, depth_to_t0);
  if (out.depth == 0 || !(sun_direction.y > kMinSunY) || medium.albedo == 0) return out;
  const Heights h = heights_of(medium, origin.y);
  const FogClip clip = clip_to_top(h, direction.y, t0, t1);
  // E(τ) = E(t0) + κ·τ along the segment (fog.h). Anchor the integral at the end where E
  // is smallest, so that its exponential has a non-positive argument.
  const double kappa = sun_rate(direction.y, sun_direction.y);
  const double anchor_t = kappa >= 0 ? clip.t0 : clip.t1;
  const double anchor_depth = depth_to_t0 + (kappa >= 0 ? 0.0 : out.depth) +  // E: eye → x(anchor) → sun
                              sun_optical_depth(medium, height_at(h, direction.y, anchor_t), h.top, sun_direction.y);
  out.sun = flush_tiny(medium.albedo * fog_transmittance_of_depth(anchor_depth) *
                       fog_exp_integral(out.depth, std::abs(kappa)));
  return out;
}

double fog_sample_lit_segment(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                              const glm::dvec3& sun_direction, double t0, double t1, double xi) {
  const Heights h = heights_of(medium, origin.y);
  const FogClip clip = clip_to_top(h, direction.y, t0, t1);
  if (clip.empty || !(sun_direction.y > kMinSunY) || medium.albedo == 0) return t0;
  const double depth = std::min(clipped_optical_depth(medium, h, direction.y, clip.t0, clip.t1), kFogFar);
  if (depth == 0) return t0;
  const double kappa = sun_rate(direction.y, sun_direction.y);
  // In τ the integrand is ∝ e^{−κτ}: sample from the end where it is largest.
  const double tau = kappa >= 0 ? sample_exponential(xi, depth, kappa)
                                : std::max(0.0, depth - sample_exponential(1 - xi, depth, -kappa));
  const double t = fog_distance_at_depth(medium, origin, direction, clip.t0, tau);
  return std::clamp(t, clip.t0, std::min(clip.t1, kFogFar));
}

}  // namespace sylva
