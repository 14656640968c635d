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
  // auto is refined on the CPU.
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

}  // namespace
}  // namespace sylva
