// fog_integrator.h — what one camera ray sees through the fog (docs/spec/fog.md, "What a pixel
// sees"), by each of the modes of "How the integral is computed":
//
//   L = T(0, t_end)·L_end + ∫₀^t_end T(0,t)·σ_s(x(t))·[p(d·s)·E_sun·V(x(t))·T_sun(x(t)) + L_sky/2] dt
//
// The sky term (L_sky/2, unshadowed) and T(0, t_end) are closed forms of fog.h in every
// mode; the modes differ only in how they handle the sun's visibility V. The sun's
// direction s (its centre) sets the phase function and T_sun; shadow rays go toward points
// of its disc. A mode needs the plants' shadows in two forms: shadow rays through the
// abstract SceneTracer (core/geometry/surface.h; only `any` is used, and only plants shadow — the
// ground never does, as in render_cpu.h) and, for the cone modes, the shadow cones' intervals
// along the ray (Hougs and Day 2001 sec. 3.3.1) through FogConeSource.
//
// Modes (Hougs and Day 2001 sec. 3.3 and 4.3 for medium and fast; docs/fog.md for the rest):
//  brute      `steps` samples stratified in the cumulative distribution of the unshadowed
//             sunlit in-scatter along the ray (fog_sample_lit_segment: sample k at the
//             share (k + ξ_k)/steps), a shadow ray toward an independent disc point at each:
//             sun = W·(1/steps)·Σ V_k with W the unshadowed integral (fog_lit_segment). Each
//             sample stands for an equal share of W, so the estimator is unbiased for any
//             stratum width and optical depth (a uniform sample weighted by its stratum's
//             closed form would be biased wherever the integrand varies across a stratum,
//             which is everywhere in thick fog) and handles unbounded rays (t_end = ∞).
//  medium     the same samples; a shadow ray only inside the cone intervals, V = 1 outside.
//  fast       V = 0 inside the cone intervals, V = 1 outside, closed form over the lit parts;
//             no shadow rays.
//  refined    one disc point per camera ray (so V along the ray is the 0/1 shadow of that
//             direction; --spp averages the disc); inside each cone interval, probes at its
//             ends and at `steps` points shared among the intervals by their unshadowed
//             weight (stratified in each one's distribution); every change of V between
//             neighbouring probes bisected (kRefinedBisections halvings, the transition put
//             at the bracket's middle); closed form over the lit parts. Outside the cones V =
//             1. Without a cone set the whole ray is one interval (nothing is assumed lit).
//  reference  like refined over the whole ray, with 8·steps probes and kReferenceBisections
//             halvings, for kReferenceDiscSamples stratified disc points (1 for a point sun)
//             averaged: converged once the probes resolve the smallest shadow (a shadow
//             narrower than a probe gap can hide in it; a gap holds 1/(8·steps) of the ray's
//             unshadowed weight, which bounds what one hidden shadow can cost).
//  map        the cone intervals (the whole shadow range without a cone set) walked through
//             each sun-space depth map (core/light/sun_map.h: one per direction of the sun's
//             disc), texel by texel: the parts in front of the map are lit, closed form over
//             them; the maps' results averaged. No shadow rays, no random numbers: exact with
//             respect to the maps (docs/fog-map.md gives their error).
//  auto       refined here (the integrator alone has no maps); render_cpu runs auto as map
//             (cpu_fog_mode, core/cpu/render_cpu.h).
//
// Early termination: the sunlit part is integrated only up to where T(0, t) falls below
// e^{−kFogNegligibleDepth} (no shadow rays beyond; what is left is < 4e-18·E_sun·p). The sky
// term and T(0, t_end) are exact to the end.
//
// Determinism: every random number comes from the caller's SampleRng (a pixel sample's
// stream, render_common.h), so a ray's result is the same on every thread.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <span>
#include <vector>

#include "core/light/fog.h"
#include "core/geometry/ray_frustum.h"
#include "core/scene/render_common.h"
#include "core/scene/scene.h"
#include "core/geometry/skin.h"
#include "core/geometry/surface.h"
#include "core/light/shadow_cones.h"
#include "core/light/sun_map.h"

namespace sylva {

// Beyond this optical depth from the eye the sunlit in-scatter is not sampled (T < 4.2e-18).
constexpr double kFogNegligibleDepth = 40;
// Halvings of a probe gap that brackets a change of visibility in refined mode: the
// transition is then placed within gap/2^7 (a gap holds 1/steps of the ray's weight), an
// error of at most 1/(128·steps) of the searched weight per edge and of either sign, far
// below what one disc point per ray and shadows narrower than a gap leave (docs/fog.md).
constexpr int kRefinedBisections = 6;
// Halvings in reference mode (fewer where the bracket reaches the resolution of t): a
// transition lands within gap/2^25 (the gap holding 1/(8·steps) of the weight), so each
// contributes an error below 1e-10 of the ray's sunlit in-scatter at the default steps.
constexpr int kReferenceBisections = 24;
// Sun-disc points per ray in reference mode (a 4×4 stratified grid over the disc).
constexpr int kReferenceDiscSamples = 16;
// Probes per ray per disc point in reference mode, per unit of `steps`.
constexpr uint32_t kReferenceProbesPerStep = 8;

// The shadow cones as the integrator queries them (Hougs and Day 2001 sec. 3.3.1): the sorted,
// disjoint intervals of t in [t_min, t_max] where origin + t·direction (direction unit) lies
// inside at least one cone — where the sun may be blocked; outside them it is not. Thread-
// safe. core/light/shadow_cones.h's ConeSet answers the same query (ConeSetFogSource below).
class FogConeSource {
 public:
  virtual ~FogConeSource() = default;
  // Clears *out, then appends the intervals.
  virtual void intervals(const Ray& ray, double t_min, double t_max, std::vector<FogInterval>* out) const = 0;
};

// The cone set as the fog integrator queries it (FogConeSource above): the
// same sorted, merged intervals. `set` must outlive the source. Thread-safe.
class ConeSetFogSource final : public FogConeSource {
 public:
  explicit ConeSetFogSource(const ConeSet& set) : set_(set) {}
  void intervals(const Ray& ray, double t_min, double t_max, std::vector<FogInterval>* out) const override;

 private:
  const ConeSet& set_;
};

// The sun as the fog sees it.
struct FogSun {
  glm::dvec3 direction{0, 1, 0};  // unit, toward the centre of the disc (s)
  double angular_radius_rad = 0;  // 0: a point sun
  glm::dvec3 radiance{0, 0, 0};   // E_sun, linear RGB
};
FogSun fog_sun_of(const Sun& sun);

// The medium of a scene with fog (precondition: scene.fog is set).
FogMedium fog_medium_of(const Scene& scene);

struct FogIntegratorOptions {
  FogIntegratorOptions(FogMode mode_ = FogMode::automatic, uint32_t steps_ = 64) : mode(mode_), steps(steps_) {}
  FogMode mode;
  uint32_t steps;  // >= 1
  // Mode map: the sun maps (one per disc direction; they must outlive the integrator).
  // Mode map needs at least one (std::invalid_argument without).
  std::span<const SunDepthMap> maps;
  // Mode map with several maps: walk one per camera ray, drawn from the ray's random
  // numbers (true), or all of them and average (false).
  bool map_per_ray = false;
};

// What one camera ray collected.
struct FogRayResult {
  glm::dvec3 inscatter{0, 0, 0};  // ∫ … dt above, linear RGB (fog.R fog.G fog.B)
  double transmittance = 1;       // T(0, t_end) (fog.T)
  uint64_t shadow_rays = 0;       // rays cast through the tracer
  uint64_t map_texels = 0;        // texels of the sun maps walked one by one (mode map)
  bool terminated_early = false;  // the sunlit part stopped at kFogNegligibleDepth
};

// Integrates camera rays through one scene's fog. Thread-safe (const); cheap to build.
class FogIntegrator {
 public:
  // `tracer` (and `cones`, when not null) must outlive the integrator; its bounds() bound
  // where shadow rays start (a point whose sun ray misses them is lit without one). `cones` is used by
  // medium, fast, refined and auto; fast needs it (std::invalid_argument without), medium
  // and refined treat a null set as one interval covering every ray.
  FogIntegrator(const FogMedium& medium, const FogSun& sun, const glm::dvec3& sky, const SceneTracer& tracer,
                const FogConeSource* cones, const FogIntegratorOptions& options);

  // The ray origin + t·direction, direction UNIT, from t = 0 to t_end (metres; +inf: to
  // infinity). `rng` is advanced.
  FogRayResult integrate(const glm::dvec3& origin, const glm::dvec3& direction, double t_end,
                         render_common::SampleRng& rng) const;

  FogMode mode() const { return mode_; }  // the mode run (auto resolved to refined)
  size_t map_count() const { return maps_.size(); }  // mode map's maps
  const FogMedium& medium() const { return medium_; }
  const FogSun& sun() const { return sun_; }

 private:
  struct CameraRay {  // the ray being integrated (direction unit)
    glm::dvec3 origin, direction;
  };
  double visible(const CameraRay& ray, double t, const glm::dvec3& toward_sun, FogRayResult* result) const;
  // The part of [a, b] that may lie in shadow: below the top of the casters' box when every
  // direction of the sun's disc climbs (above it the sun is seen), else all of it.
  FogInterval shadow_range(const CameraRay& ray, double a, double b) const;
  glm::dvec3 disc_direction(render_common::SampleRng& rng) const;
  double sun_brute(const CameraRay& ray, double a, double b, const std::vector<FogInterval>* cones,
                   render_common::SampleRng& rng, FogRayResult* result) const;
  double sun_fast(const CameraRay& ray, double a, double b, const std::vector<FogInterval>& cones) const;
  double sun_map(const CameraRay& ray, double a, double b, const std::vector<FogInterval>& cones,
                 render_common::SampleRng& rng, FogRayResult* result) const;
  double sun_refined(const CameraRay& ray, double a, double b, const std::vector<FogInterval>& search, uint32_t probes,
                     int bisections, const glm::dvec3& toward_sun, render_common::SampleRng& rng,
                     FogRayResult* result) const;

  FogMedium medium_;
  FogSun sun_;
  glm::dvec3 sky_;
  const SceneTracer& tracer_;
  const FogConeSource* cones_;
  FogMode mode_;
  uint32_t steps_;
  std::span<const SunDepthMap> maps_;
  bool map_per_ray_ = false;
  double cos_alpha_ = 1;
  AxisFrame sun_frame_{};
  bool sunlit_ = false;  // the sun lights the fog at all (radiance > 0, above the horizon)
  Aabb casters_;         // tracer.bounds(): only a sun ray that meets it can be blocked
  bool disc_climbs_ = false;  // every direction of the sun's disc has y > 0
};

}  // namespace sylva
