// Tests for core/scene/fog_integrator.h: every fog mode on a camera ray whose sunlit in-scatter is
// known exactly.
//
// The scene: spheres hanging 6–7 m above a camera ray through homogeneous fog (top at 10 m),
// found by a SceneTracer of the test's own (exact ray–sphere `any`), and a FogConeSource of
// the test's own whose "cones" are the spheres' shadow cylinders along the sun with a
// chosen margin (exact, conservative, or too thin). For a point sun the shadow along the ray
// is then known exactly: each sphere shadows the t where x(t) lies within its radius of the
// line through its centre along s (the geometry keeps every sphere sunward of the whole
// ray, so the cylinder is the whole shadow). The exact sunlit integral is fog.h's closed
// form over the lit complement (fog_test.cpp checks those closed forms against quadrature).
#include "core/scene/fog_integrator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace sylva {
namespace {

using render_common::SampleRng;
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Sphere {
  glm::dvec3 centre;
  double radius;
};

// Exact ray–sphere occlusion; no `nearest` (the fog never asks for it).
class SphereTracer final : public SceneTracer {
 public:
  explicit SphereTracer(std::vector<Sphere> spheres) : spheres_(std::move(spheres)) {}
  SurfaceHit nearest(const Ray&, double, double) const override { return {}; }
  bool any(const Ray& ray, double t_min, double t_max) const override {
    for (const Sphere& s : spheres_) {
      const glm::dvec3 w = ray.origin - s.centre;
      const double a = glm::dot(ray.direction, ray.direction), b = glm::dot(w, ray.direction);
      const double c = glm::dot(w, w) - s.radius * s.radius, disc = b * b - a * c;
      if (disc < 0) continue;
      const double t0 = (-b - std::sqrt(disc)) / a, t1 = (-b + std::sqrt(disc)) / a;
      if ((t0 > t_min && t0 < t_max) || (t1 > t_min && t1 < t_max)) return true;
    }
    return false;
  }
  Aabb bounds() const override {
    Aabb box = empty_box();
    for (const Sphere& s : spheres_) grow(box, Aabb{s.centre - s.radius, s.centre + s.radius});
    return box;
  }
  size_t memory_bytes() const override { return 0; }
  std::string describe() const override { return "test spheres"; }
  const std::vector<Sphere>& spheres() const { return spheres_; }

 private:
  std::vector<Sphere> spheres_;
};

// The t where origin + t·d lies within `radius` of the line centre + λ·s: |w⊥ + t·d⊥|² < r².
bool cylinder_interval(const glm::dvec3& origin, const glm::dvec3& d, const glm::dvec3& s, const Sphere& sphere,
                       double radius, FogInterval* out) {
  const glm::dvec3 w = origin - sphere.centre;
  const glm::dvec3 w_perp = w - glm::dot(w, s) * s, d_perp = d - glm::dot(d, s) * s;
  const double a = glm::dot(d_perp, d_perp), b = glm::dot(w_perp, d_perp), c = glm::dot(w_perp, w_perp) - radius * radius;
  const double disc = b * b - a * c;
  if (!(a > 0) || disc <= 0) return false;
  const double q = -(b + std::copysign(std::sqrt(disc), b));
  const double r0 = q / a, r1 = c / q;
  *out = {std::min(r0, r1), std::max(r0, r1)};
  return true;
}

// Sorted, merged shadow cylinders of every sphere, radius grown by `margin` (negative: thinner).
std::vector<FogInterval> shadow_intervals(const std::vector<Sphere>& spheres, const glm::dvec3& origin,
                                          const glm::dvec3& d, const glm::dvec3& s, double margin, double t_min,
                                          double t_max) {
  std::vector<FogInterval> all;
  for (const Sphere& sp : spheres) {
    FogInterval i;
    if (sp.radius + margin > 0 && cylinder_interval(origin, d, s, sp, sp.radius + margin, &i)) {
      i.t0 = std::max(i.t0, t_min), i.t1 = std::min(i.t1, t_max);
      if (i.t1 > i.t0) all.push_back(i);
    }
  }
  std::sort(all.begin(), all.end(), [](const FogInterval& x, const FogInterval& y) { return x.t0 < y.t0; });
  std::vector<FogInterval> merged;
  for (const FogInterval& i : all) {
    if (!merged.empty() && i.t0 <= merged.back().t1)
      merged.back().t1 = std::max(merged.back().t1, i.t1);
    else
      merged.push_back(i);
  }
  return merged;
}

// Cones = shadow cylinders along the sun's centre, grown by `margin`.
class CylinderCones final : public FogConeSource {
 public:
  CylinderCones(std::vector<Sphere> spheres, glm::dvec3 sun, double margin)
      : spheres_(std::move(spheres)), sun_(sun), margin_(margin) {}
  void intervals(const Ray& ray, double t_min, double t_max, std::vector<FogInterval>* out) const override {
    *out = shadow_intervals(spheres_, ray.origin, ray.direction, sun_, margin_, t_min, t_max);
    ++queries;
  }
  mutable int queries = 0;

 private:
  std::vector<Sphere> spheres_;
  glm::dvec3 sun_;
  double margin_;
};

struct ShaftScene {
  FogMedium medium = fog_medium(0.05, 0.01, 0.6, 0, 0, 10);
  FogSun sun;
  glm::dvec3 sky{0.25, 0.3, 0.4};
  std::vector<Sphere> spheres;
  glm::dvec3 eye{0, 1, 0};
  glm::dvec3 direction = glm::normalize(glm::dvec3(1, 0.02, 0.1));
  double t_end = 60;
  ShaftScene() {
    sun.direction = glm::normalize(glm::dvec3(0.05, 1, 0.03));
    sun.radiance = {3, 3, 2.8};
    // Spheres of 0.3 to 1 m, 5.5–6.5 m sunward of the ray every 4.5 m, each set off sideways by
    // up to 0.4 of its radius: shafts of light between shadows of different widths.
    const glm::dvec3 side = glm::normalize(glm::cross(direction, sun.direction));
    for (int i = 0; i < 12; ++i) {
      const double radius = 0.3 + 0.06 * i;
      spheres.push_back({eye + (3 + 4.5 * i) * direction + (6 + 0.5 * std::sin(i)) * sun.direction +
                             0.4 * radius * std::sin(2.0 * i) * side,
                         radius});
    }
  }
  // The exact sunlit integral (point sun) and the whole result's other parts.
  double exact_sun() const {
    const std::vector<FogInterval> shadow = shadow_intervals(spheres, eye, direction, sun.direction, 0, 0, t_end);
    double depth = 0, t = 0, total = 0;
    for (const FogInterval& sh : shadow) {
      const FogSegment lit = fog_lit_segment(medium, eye, direction, sun.direction, t, sh.t0, depth);
      total += lit.sun;
      depth += lit.depth + fog_optical_depth(medium, eye, direction, sh.t0, sh.t1);
      t = sh.t1;
    }
    return total + fog_lit_segment(medium, eye, direction, sun.direction, t, t_end, depth).sun;
  }
  double unshadowed_sun() const {
    return fog_lit_segment(medium, eye, direction, sun.direction, 0, t_end, 0).sun;
  }
  double phase() const { return fog_phase_schlick(medium.schlick_k, glm::dot(direction, sun.direction)); }
  glm::dvec3 sky_part() const { return 0.5 * fog_shadowed_segment(medium, eye, direction, 0, t_end, 0).sky * sky; }
  // The sunlit integral a result implies (its red channel, less the sky's share).
  double sun_of(const FogRayResult& r) const {
    return (r.inscatter.x - sky_part().x) / (phase() * sun.radiance.x);
  }
};

FogRayResult run(const ShaftScene& s, FogMode mode, uint32_t steps, const FogConeSource* cones, uint64_t seed,
                 const SceneTracer* tracer = nullptr) {
  SphereTracer own(s.spheres);
  FogIntegrator integrator(s.medium, s.sun, s.sky, tracer ? *tracer : own, cones, {mode, steps});
  SampleRng rng(seed);
  return integrator.integrate(s.eye, s.direction, s.t_end, rng);
}

TEST(FogIntegrator, TheGeometryHasShaftsAndKeepsSpheresSunwardOfTheRay) {
  const ShaftScene s;
  const std::vector<FogInterval> shadow = shadow_intervals(s.spheres, s.eye, s.direction, s.sun.direction, 0, 0, s.t_end);
  EXPECT_GE(shadow.size(), 8u);
  for (const Sphere& sp : s.spheres)
    for (double t : {0.0, s.t_end}) EXPECT_GT(glm::dot(sp.centre - (s.eye + t * s.direction), s.sun.direction), sp.radius);
  EXPECT_LT(s.exact_sun(), 0.9 * s.unshadowed_sun());
  EXPECT_GT(s.exact_sun(), 0.3 * s.unshadowed_sun());
}

TEST(FogIntegrator, WithoutOccludersEveryModeIsTheClosedForm) {
  ShaftScene s;
  s.spheres.clear();
  const CylinderCones cones(s.spheres, s.sun.direction, 0);
  for (FogMode mode : {FogMode::brute, FogMode::medium, FogMode::fast, FogMode::refined, FogMode::reference,
                       FogMode::automatic}) {
    const FogRayResult r = run(s, mode, 16, &cones, 7);
    EXPECT_NEAR(s.sun_of(r), s.unshadowed_sun(), 1e-14 * s.unshadowed_sun()) << fog_mode_name(mode);
    EXPECT_NEAR(r.transmittance, fog_transmittance(s.medium, s.eye, s.direction, 0, s.t_end), 1e-16);
    // The sky's share in each channel: (L_sky/2)·albedo·(1 − T).
    const double sky = 0.5 * s.medium.albedo * (1 - r.transmittance);
    EXPECT_NEAR(r.inscatter.z - s.sun_of(r) * s.phase() * s.sun.radiance.z, sky * s.sky.z, 1e-15) << fog_mode_name(mode);
  }
}

TEST(FogIntegrator, HandComputedHomogeneousRayWithoutShadows) {
  // A horizontal ray at 2 m under a top at 12 m, zenith sun, nothing in the way: T_sun =
  // e^{−10 σ_t} everywhere, so ∫σ_s T T_sun dt = albedo·e^{−10 σ_t}·(1 − e^{−σ_t L}), and the
  // pixel adds E_sun·p(d·s)·that + (L_sky/2)·albedo·(1 − e^{−σ_t L}); p(0) = (1 − k²)/(4π).
  const FogMedium m = fog_medium(0.04, 0.01, 0.5, 0, 0, 12);
  FogSun sun;
  sun.direction = {0, 1, 0};
  sun.radiance = {2, 2, 2};
  const SphereTracer none({});
  const FogIntegrator integrator(m, sun, {0.2, 0.2, 0.2}, none, nullptr, {FogMode::brute, 8});
  SampleRng rng(1);
  const double L = 30, sigma = 0.05, albedo = 0.8;
  const FogRayResult r = integrator.integrate({0, 2, 0}, {1, 0, 0}, L, rng);
  const double k = 0.70625, p = (1 - k * k) / (4 * 3.14159265358979323846);
  const double expected = 2 * p * albedo * std::exp(-10 * sigma) * (1 - std::exp(-sigma * L)) +
                          0.1 * albedo * (1 - std::exp(-sigma * L));
  EXPECT_NEAR(r.inscatter.x, expected, 1e-15);
  EXPECT_NEAR(r.transmittance, std::exp(-sigma * L), 1e-16);
  EXPECT_EQ(r.shadow_rays, 0u);  // nothing to cast a shadow: the tracer's box is empty
}

TEST(FogIntegrator, RefinedAndReferenceFindTheExactShadowsOfAPointSun) {
  const ShaftScene s;
  const CylinderCones cones(s.spheres, s.sun.direction, 0.05);  // conservative
  const double exact = s.exact_sun(), open = s.unshadowed_sun();
  const FogRayResult refined = run(s, FogMode::refined, 64, &cones, 3);
  // Transitions to within a probe gap / 2^7 (a gap holds ~1/64 of the weight): 24 of them.
  EXPECT_NEAR(s.sun_of(refined), exact, 24 * open / 64 / 128);
  // Reference: 512 probes, transitions within a gap / 2^25.
  const FogRayResult reference = run(s, FogMode::reference, 64, nullptr, 3);
  EXPECT_NEAR(s.sun_of(reference), exact, 24 * open / 512 / (1 << 25));
  // auto is refined in the integrator alone (render_cpu runs it as map: cpu_fog_mode).
  EXPECT_EQ(s.sun_of(run(s, FogMode::automatic, 64, &cones, 3)), s.sun_of(refined));
  // Without cones refined searches the whole ray: a shadow narrower than a probe gap (which
  // holds 1/steps of the weight) can hide there, so it takes more steps for the same answer.
  EXPECT_GT(std::abs(s.sun_of(run(s, FogMode::refined, 16, nullptr, 3)) - exact), 1e-3 * open);
  EXPECT_NEAR(s.sun_of(run(s, FogMode::refined, 2048, nullptr, 3)), exact, 24 * open / 2048 / 128);
}

// A SphereTracer that records where every shadow ray starts.
class RecordingTracer final : public SceneTracer {
 public:
  explicit RecordingTracer(const SphereTracer& inner) : inner_(inner) {}
  SurfaceHit nearest(const Ray& ray, double t_min, double t_max) const override {
    return inner_.nearest(ray, t_min, t_max);
  }
  bool any(const Ray& ray, double t_min, double t_max) const override {
    origins.push_back(ray.origin);
    return inner_.any(ray, t_min, t_max);
  }
  Aabb bounds() const override { return inner_.bounds(); }
  size_t memory_bytes() const override { return 0; }
  std::string describe() const override { return "recording"; }
  mutable std::vector<glm::dvec3> origins;

 private:
  const SphereTracer& inner_;
};

TEST(FogIntegrator, ConeModesCastShadowRaysOnlyInsideTheCones) {
  const ShaftScene s;
  const CylinderCones cones(s.spheres, s.sun.direction, 0.05);
  const std::vector<FogInterval> inside = shadow_intervals(s.spheres, s.eye, s.direction, s.sun.direction, 0.05, 0, s.t_end);
  const SphereTracer spheres(s.spheres);
  for (FogMode mode : {FogMode::medium, FogMode::refined}) {
    const RecordingTracer tracer(spheres);
    const FogRayResult r = run(s, mode, 64, &cones, 3, &tracer);
    EXPECT_EQ(r.shadow_rays, tracer.origins.size());
    EXPECT_GT(r.shadow_rays, 0u);
    for (const glm::dvec3& o : tracer.origins) {
      const double t = glm::dot(o - s.eye, s.direction);
      EXPECT_TRUE(std::any_of(inside.begin(), inside.end(), [&](const FogInterval& i) {
        return t >= i.t0 - 1e-12 && t <= i.t1 + 1e-12;
      })) << fog_mode_name(mode) << " t " << t;
    }
  }
  EXPECT_EQ(cones.queries, 2);  // one query per ray and mode
}

TEST(FogIntegrator, FastIsExactWithExactConesAndBiasedOtherwise) {
  const ShaftScene s;
  const double exact = s.exact_sun();
  const CylinderCones exact_cones(s.spheres, s.sun.direction, 0);
  const FogRayResult r = run(s, FogMode::fast, 64, &exact_cones, 1);
  EXPECT_NEAR(s.sun_of(r), exact, 1e-13 * exact);
  EXPECT_EQ(r.shadow_rays, 0u);
  // Fat cones darken (V = 0 where the sun is visible); thin ones brighten (V = 1 in shadow).
  const CylinderCones fat(s.spheres, s.sun.direction, 0.2), thin(s.spheres, s.sun.direction, -0.2);
  EXPECT_LT(s.sun_of(run(s, FogMode::fast, 64, &fat, 1)), 0.97 * exact);
  EXPECT_GT(s.sun_of(run(s, FogMode::fast, 64, &thin, 1)), 1.03 * exact);
  EXPECT_THROW(FogIntegrator(s.medium, s.sun, s.sky, SphereTracer({}), nullptr, {FogMode::fast, 8}),
               std::invalid_argument);
}

// Mean and standard error of a mode's sunlit integral over `seeds` seeds.
struct Estimate {
  double mean = 0, error = 0, shadow_rays = 0;
};
Estimate estimate(const ShaftScene& s, FogMode mode, uint32_t steps, const FogConeSource* cones, int seeds) {
  double sum = 0, sum2 = 0, rays = 0;
  for (int seed = 0; seed < seeds; ++seed) {
    const FogRayResult r = run(s, mode, steps, cones, 1000 + seed);
    const double v = s.sun_of(r);
    sum += v, sum2 += v * v, rays += r.shadow_rays;
  }
  Estimate e;
  e.mean = sum / seeds;
  e.error = std::sqrt(std::max(0.0, sum2 / seeds - e.mean * e.mean) / (seeds - 1));
  e.shadow_rays = rays / seeds;
  return e;
}

TEST(FogIntegrator, BruteAndMediumAreUnbiasedAndMediumTestsLess) {
  const ShaftScene s;
  const double exact = s.exact_sun();
  const CylinderCones cones(s.spheres, s.sun.direction, 0.05);
  const Estimate brute = estimate(s, FogMode::brute, 16, nullptr, 400);
  const Estimate medium = estimate(s, FogMode::medium, 16, &cones, 400);
  EXPECT_GT(brute.error, 0);
  EXPECT_NEAR(brute.mean, exact, 5 * brute.error);
  EXPECT_NEAR(medium.mean, exact, 5 * medium.error);
  // A shadow ray per sample, but none where the sun ray misses the spheres' box.
  EXPECT_LE(brute.shadow_rays, 16);
  EXPECT_GT(brute.shadow_rays, 8);
  EXPECT_LT(medium.shadow_rays, 0.8 * brute.shadow_rays);
  // Medium with cones that miss the shadows is biased toward light (Hougs and Day 2001 sec. 4.3).
  const CylinderCones thin(s.spheres, s.sun.direction, -0.2);
  EXPECT_GT(estimate(s, FogMode::medium, 16, &thin, 50).mean, 1.03 * exact);
}

TEST(FogIntegrator, SoftShadowsOfTheSunDiscAgreeBetweenBruteAndReference) {
  ShaftScene s;
  s.sun.angular_radius_rad = 0.05;  // a large disc: wide penumbrae
  const Estimate brute = estimate(s, FogMode::brute, 256, nullptr, 24);
  const Estimate reference = estimate(s, FogMode::reference, 16, nullptr, 6);
  EXPECT_NEAR(brute.mean, reference.mean, 5 * std::hypot(brute.error, reference.error));
  // The penumbra makes the result differ from the point sun's.
  EXPECT_GT(std::abs(reference.mean - s.exact_sun()), 10 * reference.error);
}

TEST(FogIntegrator, ReferenceHasConvergedInItsSteps) {
  ShaftScene s;
  s.sun.angular_radius_rad = 0;
  // At the default 64 steps (512 probes) every shadow of this ray is found, each edge
  // bisected to within a gap / 2^25: four times the probes change the result by less than
  // the two bounds together (24 edges), and it is the exact one.
  const double bound = 24 * s.unshadowed_sun() / 512 / (1 << 25);
  const double a = s.sun_of(run(s, FogMode::reference, 64, nullptr, 5));
  const double b = s.sun_of(run(s, FogMode::reference, 256, nullptr, 5));
  EXPECT_NEAR(a, b, 2 * bound);
  EXPECT_NEAR(a, s.exact_sun(), bound);
}

TEST(FogIntegrator, SameStreamSameResultOtherStreamOtherSamples) {
  const ShaftScene s;
  const CylinderCones cones(s.spheres, s.sun.direction, 0.05);
  for (FogMode mode : {FogMode::brute, FogMode::medium, FogMode::refined, FogMode::reference}) {
    const FogRayResult a = run(s, mode, 16, &cones, 42), b = run(s, mode, 16, &cones, 42);
    EXPECT_EQ(a.inscatter, b.inscatter) << fog_mode_name(mode);
    EXPECT_EQ(a.shadow_rays, b.shadow_rays) << fog_mode_name(mode);
  }
  EXPECT_NE(run(s, FogMode::brute, 16, nullptr, 1).inscatter, run(s, FogMode::brute, 16, nullptr, 2).inscatter);
}

TEST(FogIntegrator, ThickFogStopsSamplingWhereTransmittanceIsNegligible) {
  ShaftScene s;
  s.medium = fog_medium(2, 0.5, 0.6, 0, 0, 10);  // τ = 40 after 16 m of a 60 m ray
  const FogRayResult r = run(s, FogMode::reference, 16, nullptr, 1);
  EXPECT_TRUE(r.terminated_early);
  EXPECT_NEAR(r.transmittance / std::exp(-150.0), 1, 1e-13);  // T(0, t_end) stays exact
  ShaftScene near = s;
  near.t_end = fog_distance_at_depth(s.medium, s.eye, s.direction, 0, kFogNegligibleDepth);
  EXPECT_NEAR(s.sun_of(r), near.sun_of(run(near, FogMode::reference, 16, nullptr, 1)), 1e-15 * s.unshadowed_sun());
  // No shadow ray beyond the cut: the same count as the ray that ends there.
  EXPECT_EQ(r.shadow_rays, run(near, FogMode::reference, 16, nullptr, 1).shadow_rays);
}

TEST(FogIntegrator, SunBelowTheHorizonLeavesOnlyTheSky) {
  ShaftScene s;
  s.sun.direction = glm::normalize(glm::dvec3(1, -0.2, 0));
  const FogRayResult r = run(s, FogMode::brute, 16, nullptr, 1);
  EXPECT_EQ(r.shadow_rays, 0u);
  EXPECT_EQ(r.inscatter, s.sky_part());
}

TEST(FogIntegrator, UnboundedRaysInHeightFogAgreeAcrossModes) {
  ShaftScene s;
  s.medium = fog_medium(0.08, 0.02, 0.6, 0.3, 0);  // no top: the fog thins upward for ever
  s.direction = glm::normalize(glm::dvec3(1, 0.05, 0.1));
  s.t_end = kInf;
  s.spheres.clear();
  s.spheres.push_back({{15, 9, 1.5}, 1.5});
  const CylinderCones exact(s.spheres, s.sun.direction, 0), wide(s.spheres, s.sun.direction, 0.1);
  const FogRayResult ref = run(s, FogMode::reference, 32, nullptr, 1);
  ASSERT_TRUE(std::isfinite(ref.inscatter.x));
  EXPECT_GT(ref.transmittance, 0.0);  // a climbing ray escapes height fog
  EXPECT_NEAR(ref.transmittance, fog_transmittance(s.medium, s.eye, s.direction, 0, kInf), 1e-16);
  EXPECT_NEAR(s.sun_of(run(s, FogMode::fast, 32, &exact, 1)), s.sun_of(ref), 1e-9 * s.sun_of(ref));
  EXPECT_NEAR(s.sun_of(run(s, FogMode::refined, 32, &wide, 1)), s.sun_of(ref), 1e-4 * s.sun_of(ref));
}

TEST(FogIntegrator, ShadowRaysStartOnlyWhereTheirSunRayMeetsTheCasters) {
  // docs/fog.md "Where shadow rays start": a climbing ray in height fog without a top runs
  // to kFogFar, but every shadow ray starts below the top of the casters' box, at a point
  // whose ray toward the sun meets it; the answer is the same as with a cone set.
  ShaftScene s;
  s.medium = fog_medium(0.08, 0.02, 0.6, 0.3, 0);
  s.direction = glm::normalize(glm::dvec3(1, 0.05, 0.1));
  s.t_end = kInf;
  const SphereTracer spheres(s.spheres);
  const Aabb box = spheres.bounds();
  for (FogMode mode : {FogMode::brute, FogMode::refined, FogMode::reference}) {
    const RecordingTracer recording(spheres);
    const FogRayResult r = run(s, mode, 32, nullptr, 1, &recording);
    ASSERT_TRUE(std::isfinite(r.inscatter.x)) << fog_mode_name(mode);
    EXPECT_EQ(recording.origins.size(), r.shadow_rays) << fog_mode_name(mode);
    EXPECT_GT(r.shadow_rays, 0u) << fog_mode_name(mode);
    for (const glm::dvec3& o : recording.origins) {
      ASSERT_LE(o.y, box.hi.y) << fog_mode_name(mode);
      ASSERT_LT(glm::length(o - s.eye), 1e3) << fog_mode_name(mode);
    }
  }
  const CylinderCones exact(s.spheres, s.sun.direction, 0);
  const double fast = s.sun_of(run(s, FogMode::fast, 32, &exact, 1));
  EXPECT_NEAR(s.sun_of(run(s, FogMode::reference, 32, nullptr, 1)), fast, 1e-9 * fast);
}

// ---- Mode map ----------------------------------------------------------------------------

// Sun maps with every tile allocated, one per direction, over ±half metres around
// `centre`: each texel the height `first_hit(c, s)` of the first surface met going down the
// sun ray along s through the texel's centre c (on the plane of height 0), kNoPlant for none.
template <class FirstHit>
std::vector<SunDepthMap> exact_maps(const std::vector<glm::dvec3>& directions, const glm::dvec3& centre, double half,
                                    uint32_t size, FirstHit&& first_hit) {
  std::vector<SunDepthMap> maps;
  for (const glm::dvec3& s : directions) {
    SunMapFrame f;
    f.centre = centre, f.to_sun = s, f.half_extent_m = half, f.size = size;
    const AxisFrame a = axis_frame(s);
    f.e0 = a.e0, f.e1 = a.e1;
    const uint32_t tiles = size / SunDepthMap::kTile;
    SunDepthMap& map = maps.emplace_back(f, std::vector<uint8_t>(size_t(tiles) * tiles, 1));
    for (size_t k = 0; k < map.allocated_tiles(); ++k) {
      const uint32_t tile = map.tile_of_slot(k), tx = tile % tiles, ty = tile / tiles;
      float* h = map.slot_texels(k);
      for (uint32_t j = 0; j < SunDepthMap::kTile; ++j)
        for (uint32_t i = 0; i < SunDepthMap::kTile; ++i)
          h[j * SunDepthMap::kTile + i] =
              first_hit(map.texel_centre(tx * SunDepthMap::kTile + i, ty * SunDepthMap::kTile + j), s);
      map.finish_tile(k);
    }
  }
  return maps;
}

// The sun maps of the spheres (exact ray–sphere).
std::vector<SunDepthMap> sphere_maps(const std::vector<Sphere>& spheres, const std::vector<glm::dvec3>& directions,
                                     const glm::dvec3& centre, double half, uint32_t size) {
  return exact_maps(directions, centre, half, size, [&](const glm::dvec3& c, const glm::dvec3& s) {
    float best = SunDepthMap::kNoPlant;
    for (const Sphere& sp : spheres) {  // the line c + λ·s meets the sphere at its largest λ
      const glm::dvec3 w = c - sp.centre;
      const double b = glm::dot(w, s), disc = b * b - (glm::dot(w, w) - sp.radius * sp.radius);
      if (disc >= 0) best = std::max(best, static_cast<float>(-b + std::sqrt(disc)));
    }
    return best;
  });
}

// `k` directions spread evenly over a disc of angular radius `alpha` around unit `s` (the
// Vogel spiral of core/cpu/sun_maps.h).
std::vector<glm::dvec3> disc_directions(const glm::dvec3& s, double alpha, int k) {
  const AxisFrame f = axis_frame(s);
  std::vector<glm::dvec3> out;
  for (int i = 0; i < k; ++i) {
    const double theta = alpha * std::sqrt((i + 0.5) / k), phi = i * 2.399963229728653;
    out.push_back(glm::normalize(std::cos(theta) * s + std::sin(theta) * (std::cos(phi) * f.e0 + std::sin(phi) * f.e1)));
  }
  return out;
}

FogRayResult run_map(const ShaftScene& s, std::span<const SunDepthMap> maps, const FogConeSource* cones = nullptr,
                     bool per_ray = false, uint64_t seed = 1) {
  const SphereTracer spheres(s.spheres);
  FogIntegratorOptions o;
  o.mode = FogMode::map;
  o.maps = maps;
  o.map_per_ray = per_ray;
  const FogIntegrator integrator(s.medium, s.sun, s.sky, spheres, cones, o);
  SampleRng rng(seed);
  return integrator.integrate(s.eye, s.direction, s.t_end, rng);
}

TEST(FogIntegrator, MapModeConvergesToTheExactShadowsOfAPointSun) {
  const ShaftScene s;
  const double exact = s.exact_sun(), open = s.unshadowed_sun();
  const glm::dvec3 centre = s.eye + 27.0 * s.direction + 6.0 * s.sun.direction;
  double previous = kInf;
  for (uint32_t size : {256u, 1024u, 4096u}) {
    const double texel = 2 * 32.0 / size;
    const std::vector<SunDepthMap> maps = sphere_maps(s.spheres, {s.sun.direction}, centre, 32, size);
    const FogRayResult r = run_map(s, maps);
    EXPECT_EQ(r.shadow_rays, 0u);
    EXPECT_GT(r.map_texels, 0u);
    // Each of the 24 shadow edges lies within about a texel (over the ray's slant through
    // it) of the exact one; a metre of this ray holds at most open/10 of the weight.
    const double error = std::abs(s.sun_of(r) - exact);
    EXPECT_LT(error, 24 * 2 * texel * open / 10) << size;
    EXPECT_LT(error, previous) << size;  // finer maps come closer
    previous = error;
    // With the cones as the index the same, where the map's shadows stay inside them (a
    // texel well below their 5 cm margin), and deterministic (no random numbers).
    const CylinderCones cones(s.spheres, s.sun.direction, 0.05);
    if (texel < 0.02) {
      EXPECT_NEAR(s.sun_of(run_map(s, maps, &cones)), s.sun_of(r), 1e-12 * open) << size;
    }
    EXPECT_EQ(run_map(s, maps, nullptr, false, 9).inscatter, r.inscatter);
  }
  EXPECT_LT(previous, 2e-3 * open);
  EXPECT_THROW(FogIntegrator(s.medium, s.sun, s.sky, SphereTracer({}), nullptr, {FogMode::map, 8}),
               std::invalid_argument);
}

TEST(FogIntegrator, MapModeFollowsTheSunDiscWithSeveralMaps) {
  ShaftScene s;
  s.sun.angular_radius_rad = 0.05;  // wide penumbrae
  const glm::dvec3 centre = s.eye + 27.0 * s.direction + 6.0 * s.sun.direction;
  // The reference: many stratified disc points, each an exact (fine-probed) point-sun answer.
  const Estimate reference = estimate(s, FogMode::reference, 16, nullptr, 6);
  const std::vector<SunDepthMap> one = sphere_maps(s.spheres, disc_directions(s.sun.direction, 0.05, 1), centre, 32, 2048);
  const std::vector<SunDepthMap> many =
      sphere_maps(s.spheres, disc_directions(s.sun.direction, 0.05, 16), centre, 32, 2048);
  const double err_one = std::abs(s.sun_of(run_map(s, one)) - reference.mean);
  const double err_many = std::abs(s.sun_of(run_map(s, many)) - reference.mean);
  EXPECT_LT(err_many, 0.01 * reference.mean);
  EXPECT_LT(err_many, 0.5 * err_one);  // the disc matters, and the maps follow it
  // One map per ray, drawn at random: unbiased over the rays (the mean of many seeds).
  double sum = 0;
  for (int seed = 0; seed < 64; ++seed) sum += s.sun_of(run_map(s, many, nullptr, true, 100 + seed));
  EXPECT_NEAR(sum / 64, s.sun_of(run_map(s, many)), 0.01 * reference.mean);
}

// ---- A post's penumbra: every mode against a semi-analytic truth ----------------------

// A vertical post (a cylinder of radius r about the y axis, from y = 0 to `height`).
struct Post {
  double radius = 0.12, height = 60;
  // The t in (t_min, t_max) where the ray meets the post's solid, as an interval; false: none.
  bool hit(const Ray& ray, double t_min, double t_max) const {
    const double a = ray.direction.x * ray.direction.x + ray.direction.z * ray.direction.z;
    const double b = ray.origin.x * ray.direction.x + ray.origin.z * ray.direction.z;
    const double c = ray.origin.x * ray.origin.x + ray.origin.z * ray.origin.z - radius * radius;
    const double disc = b * b - a * c;
    if (!(a > 0) || disc < 0) return false;
    const double q = -(b + std::copysign(std::sqrt(disc), b));
    double t0 = q / a, t1 = c / q;
    if (t0 > t1) std::swap(t0, t1);
    // The part of [t0, t1] at 0 <= y <= height.
    for (const double y : {0.0, height}) {
      if (ray.direction.y == 0) continue;
      const double ty = (y - ray.origin.y) / ray.direction.y;
      if ((ray.direction.y > 0) == (y == 0)) t0 = std::max(t0, ty);
      else t1 = std::min(t1, ty);
    }
    return std::max(t0, t_min) < std::min(t1, t_max);
  }
};

class PostTracer final : public SceneTracer {
 public:
  explicit PostTracer(Post post) : post_(post) {}
  SurfaceHit nearest(const Ray&, double, double) const override { return {}; }
  bool any(const Ray& ray, double t_min, double t_max) const override { return post_.hit(ray, t_min, t_max); }
  Aabb bounds() const override {
    return {{-post_.radius, 0, -post_.radius}, {post_.radius, post_.height, post_.radius}};
  }
  size_t memory_bytes() const override { return 0; }
  std::string describe() const override { return "a post"; }

 private:
  Post post_;
};

// The scene: a low sun of a wide disc (0.02 rad: penumbrae decimetres wide a few metres
// behind the post), a camera ray 2 m up crossing the post's shadow 6 m behind it, where the
// penumbra (2·0.02·6/sin ≈ 0.3 m) is wider than the umbra (0.24 m).
struct PostScene {
  Post post;
  FogMedium medium = fog_medium(0.06, 0.01, 0.5, 0, 0, 40);
  FogSun sun;
  glm::dvec3 eye{-5.5, 2, -6}, direction = glm::normalize(glm::dvec3(0, 0, 1));
  double t_end = 12;
  PostScene() {
    sun.direction = glm::normalize(glm::dvec3(0.8, 0.45, 0.1));
    sun.angular_radius_rad = 0.02;
    sun.radiance = {2, 2, 2};
  }
  // The light the post takes from the ray, per unit of E_sun·p: ∫ w(t)·(1 − V(t)) dt with
  // w the unshadowed in-scatter density (fog.h's closed form over 4000 pieces) and V(t) the
  // uncovered fraction of the disc, each of 64 × 64 equal-area cells of the disc tested
  // exactly against the post.
  double shadow_depth() const {
    const AxisFrame f = axis_frame(sun.direction);
    std::vector<glm::dvec3> disc;
    for (int i = 0; i < 64; ++i)
      for (int j = 0; j < 64; ++j) {
        const double theta = sun.angular_radius_rad * std::sqrt((i + 0.5) / 64), phi = 2 * 3.141592653589793 * (j + 0.5) / 64;
        disc.push_back(glm::normalize(std::cos(theta) * sun.direction +
                                      std::sin(theta) * (std::cos(phi) * f.e0 + std::sin(phi) * f.e1)));
      }
    double depth = 0, total = 0;
    const int pieces = 4000;
    for (int k = 0; k < pieces; ++k) {
      const double a = t_end * k / pieces, b = t_end * (k + 1) / pieces;
      const FogSegment seg = fog_lit_segment(medium, eye, direction, sun.direction, a, b, depth);
      depth += seg.depth;
      const glm::dvec3 p = eye + 0.5 * (a + b) * direction;
      int blocked = 0;
      for (const glm::dvec3& w : disc) blocked += post.hit(Ray{p, w}, 0, kInf);
      total += seg.sun * blocked / double(disc.size());
    }
    return total;
  }
  double unshadowed() const { return fog_lit_segment(medium, eye, direction, sun.direction, 0, t_end, 0).sun; }
  // The shadow depth a mode's result implies (integrated with a black sky: all of the
  // in-scatter is sunlight).
  double depth_of(const FogRayResult& r) const {
    const double phase = fog_phase_schlick(medium.schlick_k, glm::dot(direction, sun.direction));
    return unshadowed() - r.inscatter.x / (phase * sun.radiance.x);
  }
};

TEST(FogIntegrator, EveryModeFindsTheShadowDepthOfAPostsPenumbra) {
  const PostScene s;
  const PostTracer tracer(s.post);
  const double truth = s.shadow_depth();
  ASSERT_GT(truth, 0.01 * s.unshadowed());  // the ray crosses the shadow
  // The cones: the stretch of the ray where any disc direction is blocked, found on a fine
  // grid, grown by 10 cm each way (as the photons' cones are wider than the shadow).
  struct PostCones final : public FogConeSource {
    FogInterval shadow{kInf, -kInf};
    void intervals(const Ray&, double t_min, double t_max, std::vector<FogInterval>* out) const override {
      out->clear();
      const double t0 = std::max(t_min, shadow.t0), t1 = std::min(t_max, shadow.t1);
      if (t1 > t0) out->push_back({t0, t1});
    }
  } cones;
  for (int k = 0; k <= 12000; ++k) {
    const double t = s.t_end * k / 12000;
    const glm::dvec3 p = s.eye + t * s.direction;
    const glm::dvec3 toward = p - glm::dot(p, glm::dvec3(0, 1, 0)) * glm::dvec3(0, 1, 0);  // horizontal offset
    const glm::dvec3 sh = glm::normalize(glm::dvec3(s.sun.direction.x, 0, s.sun.direction.z));
    // The horizontal distance from the post's axis to the line through p along the sun,
    // within the post's radius plus the disc's spread over that distance.
    const double along = -glm::dot(toward, sh), across = glm::length(toward + along * sh);
    if (along > 0 && across < s.post.radius + 2 * s.sun.angular_radius_rad * along)
      cones.shadow.t0 = std::min(cones.shadow.t0, t), cones.shadow.t1 = std::max(cones.shadow.t1, t);
  }
  ASSERT_LT(cones.shadow.t0, cones.shadow.t1);
  cones.shadow.t0 -= 0.1, cones.shadow.t1 += 0.1;
  auto mean_depth = [&](const FogIntegratorOptions& o, int seeds) {
    const bool cone_mode = o.mode == FogMode::refined || o.mode == FogMode::medium;
    const FogIntegrator integrator(s.medium, s.sun, glm::dvec3(0), tracer, cone_mode ? &cones : nullptr, o);
    double sum = 0;
    for (int seed = 0; seed < seeds; ++seed) {
      SampleRng rng(500 + seed);
      sum += s.depth_of(integrator.integrate(s.eye, s.direction, s.t_end, rng));
    }
    return sum / seeds;
  };
  // The bounds: refined within 5 % (over pixels, i.e. many disc points; with its
  // cones: searching the whole 12 m ray, its 64 probes lie 19 cm apart, as wide as the
  // shadow, and it comes 6 % short), brute and medium at their default 64 steps within
  // 15 %, the map within 5 %.
  EXPECT_NEAR(mean_depth({FogMode::refined, 64}, 64), truth, 0.05 * truth);
  EXPECT_NEAR(mean_depth({FogMode::brute, 64}, 64), truth, 0.15 * truth);
  EXPECT_NEAR(mean_depth({FogMode::medium, 64}, 64), truth, 0.15 * truth);
  EXPECT_NEAR(mean_depth({FogMode::reference, 64}, 4), truth, 0.05 * truth);
  // The map: 4 directions over the disc, 1024² over ±4 m; a texel's height is the first
  // post surface down its sun ray, found by bisection on "hit before" from 100 m up.
  const std::vector<SunDepthMap> maps = exact_maps(
      disc_directions(s.sun.direction, s.sun.angular_radius_rad, 4), {0, 4, 0}, 4, 1024,
      [&](const glm::dvec3& c, const glm::dvec3& d) {
        const Ray down{c + 100.0 * d, -d};
        double lo = 0, hi = 200;
        if (!s.post.hit(down, lo, hi)) return SunDepthMap::kNoPlant;
        for (int step = 0; step < 60; ++step) {
          const double mid = 0.5 * (lo + hi);
          (s.post.hit(down, 0, mid) ? hi : lo) = mid;
        }
        return static_cast<float>(100 - hi);
      });
  FogIntegratorOptions o(FogMode::map, 64);
  o.maps = maps;
  EXPECT_NEAR(mean_depth(o, 1), truth, 0.05 * truth);
  // One map toward the disc's centre alone sees no penumbra, but a hard shadow of the
  // same width: the depth is still close (a post is a band), the profile is not.
  o.maps = std::span<const SunDepthMap>(maps).subspan(0, 1);
  EXPECT_NEAR(mean_depth(o, 1), truth, 0.1 * truth);
}

}  // namespace
}  // namespace sylva
