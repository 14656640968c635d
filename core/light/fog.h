// fog.h — the participating medium of docs/spec/fog.md and its closed forms: density,
// Schlick's phase function, optical depth and transmittance along any segment, toward the
// sun, and the single-scattering integrals over a lit segment. Double precision; every
// function is shaped so that a GLSL twin of the same name (float, no expm1/log1p) can
// follow it line by line: scalar arguments, no allocation, few branches, each branch a
// select on a limit case. docs/fog.md derives the formulas and lists the accuracy that
// tests/light/fog_test.cpp measures against a long-double quadrature.
//
// Units and frames: world space, metres, Y up; coefficients per metre, grey (the same in R,
// G, B). A ray is x(t) = origin + t·direction with `direction` UNIT, so t is in metres.
// The medium is stratified (it depends on y only), so only the y components of points and
// directions enter; the x and z components are accepted for readability and ignored.
//
// The medium (docs/spec/fog.md): ρ(y) = exp(−h·(y − ground)) for y <= top, 0 above top (top = +inf:
// no ceiling); σ_s(y) = sigma_s·ρ(y), σ_a(y) = sigma_a·ρ(y), σ_t = σ_s + σ_a. Below the
// ground the exponential continues (camera rays never go there: they stop at the ground).
//
// Numerical hazards handled here, each a named case in the tests:
//  - σ → 0 and h·Δy → 0: every "(1 − e^{−x})/x" is fog_exprel (expm1 based, series at 0),
//    never (1 − exp(−x))/x, so σ = 1e-12 and horizontal rays (the 0/0 of height fog) are
//    ordinary cases, as is a camera ray parallel to the sun (d_y = s_y).
//  - τ large: transmittance is exactly 0 beyond kFogMaxDepth (e^{−700} ≈ 1e-304, above the
//    denormals), densities below e^{−kFogMaxExponent} are exactly 0 and above
//    e^{+kFogMaxExponent} clamped, so nothing underflows into denormals or overflows to
//    inf·0; the integrals over a lit segment factor out their largest value first, so their
//    exponentials are always of non-positive arguments.
//  - unbounded rays (t = +inf): lengths are clamped to kFogFar (1e300) before they meet a
//    rate, so ∞·0 never occurs: an infinite ray in homogeneous fog has τ = ∞ (σ > 0) or 0
//    (σ = 0), in height fog climbing at d_y > 0 the finite σ_t(y0)/(h·d_y).
//  - the sun near or below the horizon: T_sun → 0 smoothly as s_y → 0+; s_y <= 0 gives
//    T_sun = 0 in any fog with σ_t > 0 below `top` (the path toward the sun never leaves
//    it), and no sunlit in-scatter (docs/spec/fog.md: V = 0 when the sun is below the horizon).
#pragma once

#include <glm/vec3.hpp>
#include <limits>

namespace sylva {

constexpr double kFogInfinity = std::numeric_limits<double>::infinity();
// Optical depths beyond this give T = 0 exactly (e^{−700} ≈ 9.9e-305 is still normal).
constexpr double kFogMaxDepth = 700;
// A density exponent −h·(y − ground) below −kFogMaxExponent gives ρ = 0 exactly; above
// +kFogMaxExponent it is clamped there (only reached far below the ground).
constexpr double kFogMaxExponent = 600;
// Lengths (metres or optical depths) are clamped here before they meet a rate, so an
// unbounded ray never forms ∞·0.
constexpr double kFogFar = 1e300;

// The medium with its derived constants. Build it with fog_medium; no field is ever NaN.
struct FogMedium {
  double sigma_s = 0;         // scattering at the ground, 1/m, >= 0
  double sigma_a = 0;         // absorption at the ground, 1/m, >= 0
  double sigma_t = 0;         // sigma_s + sigma_a
  double albedo = 0;          // sigma_s / sigma_t, in [0, 1]; 0 where sigma_t = 0
  double height_falloff = 0;  // h, 1/m, >= 0 (0: homogeneous)
  double ground = 0;          // y where ρ = 1, metres
  double top = kFogInfinity;  // y above which ρ = 0, metres, >= ground; +inf: no ceiling
  double g = 0;               // Henyey–Greenstein asymmetry the phase approximates
  double schlick_k = 0;       // fog_schlick_k(g), |k| < 1
};

// The medium of docs/spec/fog.md. Preconditions (the scene reader checks them and reports located
// errors): sigma_s, sigma_a, height_falloff >= 0 and finite; |g| < kFogMaxAbsG; top >=
// ground (or +inf).
FogMedium fog_medium(double sigma_s, double sigma_a, double g, double height_falloff, double ground,
                     double top = kFogInfinity);

// An interval of t (metres along a unit ray direction), t0 < t1: a part of a ray that is lit,
// or that a shadow cone covers.
struct FogInterval {
  double t0 = 0, t1 = 0;
};

// ---- Phase function -------------------------------------------------------------------

// The largest |g| for which Schlick's k = 1.55g − 0.55g³ stays below 1 in magnitude: the
// root of 0.55g² + 0.55g − 1 = 0 (k(g) = 1 factors as (g − 1)(0.55g² + 0.55g − 1) = 0),
// g* = (√2.5025 − 0.55)/1.1 = 0.93811745632330678…. At and beyond it the phase function is no longer
// a distribution (|k| >= 1), so the scene reader rejects |g| >= g*.
constexpr double kFogMaxAbsG = 0.9381174563233;  // g* rounded down (k(g*) < 1 in double)

// k = 1.55g − 0.55g³ (Blasi–Schlick's fit of Henyey–Greenstein's g).
double fog_schlick_k(double g);

// Schlick's phase function p(cos θ) = (1 − k²) / (4π (1 − k cos θ)²), 1/sr, normalised over
// the sphere for |k| < 1. cos θ = d·s with d the camera ray's direction (from the eye into
// the scene) and s the direction toward the sun: k > 0 (g > 0) is brightest looking toward
// the sun (cos θ = 1, forward scattering of the sunlight into the eye).
double fog_phase_schlick(double k, double cos_theta);

// ---- Limit-safe elementary functions --------------------------------------------------

// exprel(x) = (e^x − 1)/x, 1 at x = 0 (series for |x| < 1e-4, expm1 otherwise); for
// x > kFogMaxDepth it is clamped to exprel(kFogMaxDepth) (callers only pass x <= 0).
double fog_exprel(double x);

// lnrel(x) = −ln(1 − x)/x for x < 1, 1 at x = 0 (series for |x| < 1e-4, log1p otherwise);
// +inf for x >= 1. The inverse of exprel's role: −ln(1 − x) = x·lnrel(x).
double fog_lnrel(double x);

// ∫₀^length e^{−rate·s} ds = length·exprel(−rate·length), for length >= 0 (may be +inf:
// clamped to kFogFar) and rate >= 0: length at rate 0, 1/rate for an unbounded length.
double fog_exp_integral(double length, double rate);

// e^{−depth} for depth >= 0 (may be +inf); exactly 0 beyond kFogMaxDepth.
double fog_transmittance_of_depth(double depth);

// ---- The medium along rays ------------------------------------------------------------

// ρ(y): 1 at the ground, exp(−h·(y − ground)) below top, 0 above top (see the clamps above).
double fog_density(const FogMedium& medium, double y);

// The part of [t0, t1] (t0 <= t1, t1 may be +inf) where origin + t·direction lies at or
// below top; `empty` when there is none (t0, t1 are then meaningless).
struct FogClip {
  double t0 = 0, t1 = 0;
  bool empty = true;
};
FogClip fog_clip_to_top(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                        double t0, double t1);

// Optical depth τ(t0, t1) = ∫ σ_t(x(t)) dt over [t0, t1] (t1 may be +inf; 0 when t1 <= t0),
// in closed form for every h >= 0, accurate as the segment becomes horizontal:
//   τ = σ_t·ρ(y_low)·exp_integral(L, h·|d_y|)
// with L the length of the part below top and y_low its lower end (where ρ is largest).
// Result in [0, +inf]: a ray that never leaves the fog (unbounded and homogeneous, or
// horizontal) gets a depth far beyond kFogMaxDepth (lengths are clamped to kFogFar), T = 0.
double fog_optical_depth(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                         double t0, double t1);

// T(t0, t1) = e^{−τ(t0, t1)}.
double fog_transmittance(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                         double t0, double t1);

// Optical depth from `point` toward the sun (unit `sun_direction`) to the fog's top or to
// infinity. Homogeneous fog without a top never ends: +inf (T_sun = 0) for σ_t > 0 — a
// sun over an unbounded homogeneous fog lights nothing; give the fog a `top` (docs/spec/fog.md).
// Height fog without a top: σ_t·ρ(y)/(h·s_y), finite for s_y > 0. s_y <= 0: +inf below the
// top (the path stays in the fog), 0 above it for s_y = 0.
double fog_sun_optical_depth(const FogMedium& medium, const glm::dvec3& point, const glm::dvec3& sun_direction);

// T_sun(point) = e^{−fog_sun_optical_depth}: what multiplies a surface's (or the fog's) sunlight.
double fog_sun_transmittance(const FogMedium& medium, const glm::dvec3& point, const glm::dvec3& sun_direction);

// The t at which the optical depth from t0 reaches `depth` (>= 0) along the ray: t0 +
// (depth/u0)·lnrel(h·d_y·depth/u0) with u0 = σ_t(x(t0)), stopping at the top; +inf where the
// ray's remaining optical depth (to the top or to infinity) is <= depth. Precondition: x(t0)
// at or below top (clip first). The inverse of fog_optical_depth(…, t0, t).
double fog_distance_at_depth(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                             double t0, double depth);

// ---- Single scattering over a lit segment ---------------------------------------------

// What the fog scatters toward the eye over a segment [t0, t1] of the camera ray x(t) =
// origin + t·direction, per unit of the light's radiance:
//   sun = ∫ σ_s(x(t))·T(0, t)·T_sun(x(t)) dt   (× E_sun·p(d·s)·V for the sunlight; V = 1 here)
//   sky = ∫ σ_s(x(t))·T(0, t) dt               (× L_sky/2 for the sky's ambient light)
// where T(0, t) = e^{−depth_to_t0}·T(t0, t). Closed forms for any stratified profile: along
// the ray, σ_s = albedo·σ_t and the sun's optical depth falls by d_y/s_y per unit of the
// ray's optical depth τ (both are ∫σ_t dy over the same heights, divided by d_y and s_y), so
// in τ the sunlit integrand is albedo·e^{−E(0) − κτ} with κ = (s_y − d_y)/s_y and E the
// total optical depth eye → x → sun:
//   sun = albedo·e^{−min(E(t0), E(t1))}·exp_integral(τ01, |κ|)   (anchored at the larger end)
//   sky = albedo·e^{−depth_to_t0}·(1 − e^{−τ01})                  (−expm1, no cancellation)
// Parts of [t0, t1] above top contribute nothing. s_y <= 0: sun = 0 (docs/spec/fog.md: V = 0 below
// the horizon; likewise for s_y <= 1e-300, where T_sun = 0 but on the top itself). Results
// are finite, >= 0, never NaN, never subnormal (below 1e-300 they are 0).
struct FogSegment {
  double sun = 0;    // ∫ σ_s·T(0,t)·T_sun dt, dimensionless (1/m × m)
  double sky = 0;    // ∫ σ_s·T(0,t) dt
  double depth = 0;  // τ(t0, t1): add it to depth_to_t0 for the next segment
};
FogSegment fog_lit_segment(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                           const glm::dvec3& sun_direction, double t0, double t1, double depth_to_t0);

// Like fog_lit_segment but in shadow (V = 0): only the sky term and the depth.
FogSegment fog_shadowed_segment(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                                double t0, double t1, double depth_to_t0);

// The t in [t0, t1] whose share of fog_lit_segment(…).sun up to it is `xi` in [0, 1): the
// inverse of the unshadowed sunlit in-scatter's cumulative distribution over the segment, so
// xi uniform gives t with density ∝ σ_s·T·T_sun (importance sampling of the sunlit
// integrand; stratified xi gives stratified samples). Returns t0 when the segment has no
// sunlit in-scatter (sun below the horizon, no fog, empty segment).
double fog_sample_lit_segment(const FogMedium& medium, const glm::dvec3& origin, const glm::dvec3& direction,
                              const glm::dvec3& sun_direction, double t0, double t1, double xi);

}  // namespace sylva
