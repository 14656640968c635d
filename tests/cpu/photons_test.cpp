// Tests for core/cpu/photons.h: sun photons, shadow vectors (Hougs and Day 2001 sec. 3.1, Fig. 2b),
// the automatic cone parameters (sec. 6.1) and the cones built once per (plants, sun).
#include "core/cpu/photons.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <glm/geometric.hpp>
#include <random>
#include <string>

#include "tests/support/test_scenes.h"
#include "core/cpu/render_cpu.h"
#include "core/util/math.h"
#include "tests/support/plants.h"
#include "core/cpu/crotch_tracer.h"
#include "core/geometry/crotch_mesh.h"
#include "tests/support/limb_crotch.h"

namespace sylva {
namespace {

constexpr double kSunRadiusDeg = 0.27;

Scene cylinder_scene(const glm::dvec3& to_sun, double sun_radius_deg, double ground = -100) {
  Scene s = test::scene_around(test::cylinder(0.5, 0, 4), {10, 2, 0}, {0, 2, 0}, 64, 48, ground);
  s.sun.direction = glm::normalize(to_sun);
  s.sun.angular_radius_deg = sun_radius_deg;
  return s;
}

SceneGeometry exact_geometry(const Scene& s) {
  GeometryOptions g;
  g.cull = false;
  g.relief = false;
  return build_scene_geometry(s, {}, g);
}

// The pine preset, grown once: thousands of frusta of every size and direction.
const Scene& pine_scene() {
  static const Scene scene = [] {
    Scene s = test::scene_around(test::grow_preset("pine"), {6, 2, 6}, {0, 2, 0}, 64, 48, 0);
    s.sun.direction = glm::normalize(glm::dvec3(0.8, 0.9, 0.45));
    s.sun.angular_radius_deg = kSunRadiusDeg;
    return s;
  }();
  return scene;
}

void expect_same_vectors(const ShadowVectors& a, const ShadowVectors& b, const char* what) {
  ASSERT_EQ(a.vectors.size(), b.vectors.size()) << what;
  EXPECT_EQ(a.origin, b.origin) << what;
  for (size_t i = 0; i < a.vectors.size(); ++i) {
    ASSERT_EQ(a.vectors[i].position, b.vectors[i].position) << what << ", vector " << i;
    ASSERT_EQ(a.vectors[i].direction, b.vectors[i].direction) << what << ", vector " << i;
    ASSERT_EQ(a.vectors[i].frustum, b.vectors[i].frustum) << what << ", vector " << i;
  }
}

TEST(SunPhotons, AreTheSameForEveryThreadCountAndSeedDependent) {
  const SceneGeometry g = exact_geometry(pine_scene());
  SunPhotonOptions o;
  o.photons = 300'000;
  o.seed = 7;
  o.threads = 1;
  const SunPhotons one = trace_sun_photons(g.frusta, pine_scene().sun, o);
  ASSERT_GT(one.vectors.vectors.size(), 1000u);
  EXPECT_EQ(one.traced, o.photons);
  for (unsigned threads : {2u, 5u}) {
    o.threads = threads;
    expect_same_vectors(one.vectors, trace_sun_photons(g.frusta, pine_scene().sun, o).vectors, "threads");
  }
  o.seed = 8;
  const SunPhotons other = trace_sun_photons(g.frusta, pine_scene().sun, o);
  bool differ = other.vectors.vectors.size() != one.vectors.vectors.size();
  for (size_t i = 0; !differ && i < one.vectors.vectors.size(); ++i)
    differ = other.vectors.vectors[i].position != one.vectors.vectors[i].position;
  EXPECT_TRUE(differ) << "another seed, other photons";
}

TEST(SunPhotons, OccupancyMaskChangesNoShadowVector) {
  // The mask only skips photons it proves to miss: with it off, Embree traces every
  // photon and finds exactly the same vectors (the pine: needles of every direction).
  const SceneGeometry g = exact_geometry(pine_scene());
  for (const glm::dvec3& to_sun : {glm::dvec3(0.8, 0.9, 0.45), glm::dvec3(-0.2, 0.15, 1), glm::dvec3(0, 1, 0)}) {
    Sun sun = pine_scene().sun;
    sun.direction = glm::normalize(to_sun);
    for (double radius_deg : {kSunRadiusDeg, 0.0, 3.0}) {
      sun.angular_radius_deg = radius_deg;
      SunPhotonOptions o;
      o.photons = 120'000;
      o.seed = 3;
      const SunPhotons masked = trace_sun_photons(g.frusta, sun, o);
      o.occupancy_mask = false;
      const SunPhotons all = trace_sun_photons(g.frusta, sun, o);
      EXPECT_GT(all.vectors.vectors.size(), 1000u);
      const std::string what = "mask, sun (" + std::to_string(to_sun.x) + ", " + std::to_string(to_sun.y) + ", " +
                               std::to_string(to_sun.z) + "), radius " + std::to_string(radius_deg);
      expect_same_vectors(all.vectors, masked.vectors, what.c_str());
    }
  }
}

TEST(SunPhotons, ShadowVectorsLieOnTheCylindersFarSide) {
  // A vertical cylinder of radius 0.5 lit from the side: each photon that hits leaves it
  // on the far half of its surface, moving away from the sun within the sun's disc.
  const glm::dvec3 to_sun = glm::normalize(glm::dvec3(1, 0.3, 0.2));
  const Scene s = cylinder_scene(to_sun, kSunRadiusDeg);
  const SceneGeometry g = exact_geometry(s);
  SunPhotonOptions o;
  o.photons = 100'000;
  const SunPhotons p = trace_sun_photons(g.frusta, s.sun, o);
  ASSERT_GT(p.vectors.vectors.size(), 1000u);
  const double alpha = kSunRadiusDeg * kRadPerDeg;
  const glm::dvec3 horizontal_sun = glm::normalize(glm::dvec3(to_sun.x, 0, to_sun.z));
  for (const ShadowVector& v : p.vectors.vectors) {
    const glm::dvec3 x = p.vectors.origin + glm::dvec3(v.position);
    const glm::dvec3 radial(x.x, 0, x.z);
    // On the side (or a cap): within float rounding of radius 0.5, 0 <= y <= 4.
    const bool on_side = std::abs(glm::length(radial) - 0.5) < 2e-6;
    const bool on_cap = std::abs(x.y) < 2e-6 || std::abs(x.y - 4) < 2e-6;
    ASSERT_TRUE(on_side || on_cap) << x.x << " " << x.y << " " << x.z;
    if (on_side) {
      EXPECT_LE(glm::dot(glm::normalize(radial), horizontal_sun), 1e-3);  // the far half
    }
    const glm::dvec3 d(v.direction);
    EXPECT_NEAR(glm::length(d), 1, 1e-6);
    // The angle from the float direction (atan2: acos loses digits near 1).
    const glm::dvec3 du = glm::normalize(d);
    EXPECT_LE(std::atan2(glm::length(glm::cross(du, -to_sun)), glm::dot(du, -to_sun)), alpha + 1e-6);
    EXPECT_EQ(v.frustum, 0u);
  }
}

TEST(SunPhotons, HitsInProportionToTheProjectedArea) {
  // A parallel sun: the cylinder's shadow on the emitter disc is a rectangle 1 m wide and
  // 4·sin(90° − elevation) tall plus the caps' ellipses; photons are uniform on the disc.
  const glm::dvec3 to_sun = glm::normalize(glm::dvec3(1, 0, 0));  // horizontal: area 1 × 4
  const Scene s = cylinder_scene(to_sun, 0);
  const SceneGeometry g = exact_geometry(s);
  SunPhotonOptions o;
  o.photons = 400'000;
  const SunPhotons p = trace_sun_photons(g.frusta, s.sun, o);
  const double disc_area = kPi * p.emitter.disc_radius_m * p.emitter.disc_radius_m;
  const double expected = o.photons * 4.0 / disc_area;
  // Binomial 4σ (the low-discrepancy positions do far better).
  EXPECT_NEAR(double(p.vectors.vectors.size()), expected, 4 * std::sqrt(expected));
}

TEST(SunPhotons, DirectionsAreUniformOverTheSunsDisc) {
  const glm::dvec3 to_sun = glm::normalize(glm::dvec3(0.3, 1, 0.1));
  const Scene s = cylinder_scene(to_sun, 2.0);  // a large sun for the statistics
  const SceneGeometry g = exact_geometry(s);
  SunPhotonOptions o;
  o.photons = 200'000;
  const SunPhotons p = trace_sun_photons(g.frusta, s.sun, o);
  ASSERT_GT(p.vectors.vectors.size(), 5000u);
  const double alpha = 2.0 * kRadPerDeg;
  double mean_one_minus_cos = 0, max_angle = 0;
  for (const ShadowVector& v : p.vectors.vectors) {
    const double c = -glm::dot(glm::dvec3(v.direction), to_sun);
    mean_one_minus_cos += 1 - c;
    max_angle = std::max(max_angle, std::acos(std::min(1.0, c)));
  }
  mean_one_minus_cos /= p.vectors.vectors.size();
  // 1 − cos θ uniform on [0, 1 − cos α]: its mean is half of 1 − cos α.
  const double one_minus_cos_alpha = 2 * std::pow(std::sin(alpha / 2), 2);
  EXPECT_NEAR(mean_one_minus_cos / (0.5 * one_minus_cos_alpha), 1, 0.03);
  EXPECT_LE(max_angle, alpha * 1.0001);
  EXPECT_GE(max_angle, alpha * 0.99);
}

TEST(SunEmitter, CoversTheBoundingSphereForEveryDirectionOfTheSunsDisc) {
  const SceneGeometry g = exact_geometry(pine_scene());
  Sun sun = pine_scene().sun;
  sun.angular_radius_deg = 5;  // exaggerated: the cover must hold for any α
  const SunEmitter e = sun_emitter(g.frusta, sun);
  EXPECT_GT(e.sphere_radius_m, 1);
  const AxisFrame f = axis_frame(e.to_sun);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const double alpha = 5 * kRadPerDeg;
  for (int i = 0; i < 100000; ++i) {
    // A point of the sphere and a direction toward the sun within α.
    glm::dvec3 q;
    do q = glm::dvec3(u(rng), u(rng), u(rng));
    while (glm::dot(q, q) > 1);
    const glm::dvec3 point = e.centre + e.sphere_radius_m * q;
    const double h = (0.5 * (u(rng) + 1)) * (1 - std::cos(alpha)), phi = kPi * u(rng);
    const glm::dvec3 up = (1 - h) * e.to_sun + std::sqrt(h * (2 - h)) * (std::cos(phi) * f.e0 + std::sin(phi) * f.e1);
    // Back along it to the emitter's plane: within the disc.
    const double t = glm::dot(e.disc_centre - point, e.to_sun) / glm::dot(up, e.to_sun);
    ASSERT_GT(t, 0);
    const glm::dvec3 start = point + t * up;
    ASSERT_LE(glm::length(start - e.disc_centre), e.disc_radius_m) << i;
  }
}

TEST(SunPhotons, CancelledBeforeTheStartTracesNothing) {
  const Scene s = cylinder_scene({1, 0.3, 0.2}, kSunRadiusDeg);
  const SceneGeometry g = exact_geometry(s);
  std::atomic<bool> cancel{true};
  SunPhotonOptions o;
  o.photons = 100'000;
  o.cancel = &cancel;
  const SunPhotons p = trace_sun_photons(g.frusta, s.sun, o);
  EXPECT_TRUE(p.cancelled);
  EXPECT_EQ(p.traced, 0u);
  EXPECT_TRUE(p.vectors.vectors.empty());
}

// ---- Cones from photons ----------------------------------------------------------------

TEST(SunCones, SunBelowTheHorizonTracesNothing) {
  const Scene s = cylinder_scene({1, -0.1, 0}, kSunRadiusDeg);
  const SceneGeometry g = exact_geometry(s);
  const auto c = build_sun_cones(g, s, {});
  EXPECT_EQ(c->photons, 0u);
  EXPECT_EQ(c->cones.size(), 0u);
  EXPECT_TRUE(c->passes.empty());
}

TEST(SunCones, AFlatOccludersConesFillItsShadowAndTheChoiceIsAsGoodAsAnyTried) {
  // A short fat cylinder (a table top, radius 1.5, 0.1 thick) at y = 3 under a high sun:
  // its shadow is a slanted cylinder down to the ground.
  Skeleton top = test::cylinder(1.5, 3, 3.1);
  Scene s = test::scene_around(top, {6, 2, 6}, {0, 2, 0}, 64, 48, 0);
  s.sun.direction = glm::normalize(glm::dvec3(0.3, 1, 0.2));
  s.sun.angular_radius_deg = kSunRadiusDeg;
  const SceneGeometry g = exact_geometry(s);
  SunConeOptions o;
  o.photons.photons = 200'000;
  o.photons.seed = 2;
  const auto c = build_sun_cones(g, s, o);
  ASSERT_TRUE(c->automatic);
  const AutoConeReport& a = *c->automatic;
  ASSERT_FALSE(a.candidates.empty());
  // The descent stops where no neighbour gains more than the noise (0.005): nothing it
  // tried is better than the choice by more than that.
  for (const ConeCandidate& k : a.candidates)
    EXPECT_GE(k.coverage.error(), a.candidates[a.chosen].coverage.error() - 0.005 - 1e-12);
  EXPECT_EQ(c->params.p1, a.candidates[a.chosen].params.p1);
  EXPECT_GT(a.density_per_m2, 0);
  EXPECT_NE(a.describe().find("automatic"), std::string::npos);
  ASSERT_TRUE(c->coverage);
  EXPECT_GT(c->coverage->shadowed, 1000u);
  EXPECT_LT(c->coverage->missed_shadow, 0.15);
  EXPECT_LT(c->coverage->covered_lit, 0.15);
  EXPECT_GT(c->cones.size(), 10u);
  // Every cone ends below the ground (y = 0) or at the length limit.
  for (const ShadowCone& k : c->cones.cones()) {
    const glm::dvec3 end = k.base + k.end_s() * k.axis;
    const double horizontal = std::sqrt(1 - k.axis.y * k.axis.y);
    EXPECT_LE(end.y + k.radius_at(k.end_s()) * horizontal, 1e-6);
  }
  // Photons, parameters, cones, coverage: four passes with their cost.
  ASSERT_EQ(c->passes.size(), 4u);
  EXPECT_EQ(c->passes[0].name, "photons");
  EXPECT_EQ(c->passes[1].name, "cone params");
  EXPECT_EQ(c->passes[2].name, "cones");
  EXPECT_EQ(c->passes[3].name, "cone coverage");
}

TEST(SunCones, GivenParametersAreUsedAndTheResultIsReproducible) {
  const SceneGeometry g = exact_geometry(pine_scene());
  SunConeOptions o;
  o.photons.photons = 100'000;
  o.params = ConeParams{41, 8, 8, 8, 2.5};
  o.coverage_points = 0;
  const auto a = build_sun_cones(g, pine_scene(), o);
  o.photons.threads = 1;
  const auto b = build_sun_cones(g, pine_scene(), o);
  EXPECT_FALSE(a->automatic);
  EXPECT_FALSE(a->coverage);
  EXPECT_EQ(a->params.p1, 41u);
  ASSERT_EQ(a->cones.size(), b->cones.size());
  ASSERT_GT(a->cones.size(), 10u);
  for (size_t i = 0; i < a->cones.size(); ++i) {
    EXPECT_EQ(a->cones.cones()[i].base, b->cones.cones()[i].base);
    EXPECT_EQ(a->cones.cones()[i].radius_base_m, b->cones.cones()[i].radius_base_m);
  }
}

}  // namespace
}  // namespace sylva

namespace sylva {
namespace {

// The one square leaf of test_scenes.h (z = 0, −1 <= x <= 0, 1 <= y <= 2) on its thin
// stem, the sun along (0, 1, 1): photons that meet the leaf stop there.
TEST(SunPhotonsLeaves, ALeafStopsPhotonsAtItsHitPoint) {
  const Scene s = test::leaf_shadow_scene();
  const SceneGeometry g = exact_geometry(s);
  ASSERT_NE(g.leaves, nullptr);
  SunPhotonOptions o;
  o.photons = 20000;
  const SunPhotons with = SunPhotonTracer(g.frusta, s.sun, 0, g.leaves, g.plant_of_frustum).trace(o);
  const SunPhotons without = SunPhotonTracer(g.frusta, s.sun, 0).trace(o);
  size_t on_leaf = 0;
  for (const ShadowVector& v : with.vectors.vectors) {
    const glm::dvec3 p = with.vectors.origin + glm::dvec3(v.position);
    if (std::abs(p.z) > 1e-5 || p.x > -0.03) continue;  // on the stem
    ++on_leaf;
    EXPECT_GE(p.x, -1 - 1e-5);
    EXPECT_LE(p.y, 2 + 1e-5);
    EXPECT_GE(p.y, 1 - 1e-5);
    EXPECT_EQ(v.frustum, 0u);  // the plant's first frustum
  }
  // The leaf is 1 m² seen at 45°; the stem a few cm wide: most vectors are the leaf's.
  EXPECT_GT(on_leaf, with.vectors.vectors.size() / 2);
  EXPECT_GT(with.vectors.vectors.size(), 4 * without.vectors.vectors.size());
  // Under the leaf's shadow the sun is blocked; the tracer without leaves sees through.
  const SunPhotonTracer tracer(g.frusta, s.sun, 0, g.leaves, g.plant_of_frustum);
  EXPECT_TRUE(tracer.toward_sun_blocked({-0.5, 0, -1.5}));
  EXPECT_FALSE(SunPhotonTracer(g.frusta, s.sun, 0).toward_sun_blocked({-0.5, 0, -1.5}));
}

// The blended crotches' fillets (crotch_tracer.h) stop photons as the frusta do: a photon
// aimed at a point of a fillet outside the exact frusta stops there (first_hit, trace's own
// test), where the exact frusta let it pass; the mask covers the balls (it changes no
// vector); every vector names a frustum of the plant.
TEST(SunPhotonsCrotches, TheFilletsStopPhotonsWhereTheExactFrustaLetThemPass) {
  Scene s = test::scene_around(test::limb_on_trunk(), {4, 1.5, 3}, {0, 1.2, 0}, 64, 48);
  s.sun.direction = glm::normalize(glm::dvec3(0.5, 1, 0.3));
  s.sun.angular_radius_deg = kSunRadiusDeg;
  GeometryOptions no_cull;
  no_cull.cull = false;
  SkinOptions blended;
  blended.blend_crotches = true;
  const SceneGeometry g = build_scene_geometry(s, blended, no_cull);
  ASSERT_NE(g.crotches, nullptr);
  ASSERT_EQ(g.crotches->count(), 1u);
  const SunPhotonTracer with(g.frusta, s.sun, 0, nullptr, g.plant_of_frustum, g.crotches.get());
  const SunPhotonTracer without(g.frusta, s.sun, 0, nullptr, g.plant_of_frustum);
  const glm::dvec3 to_sun = glm::normalize(s.sun.direction);
  // Points of the fillet (its mesh's vertices lie on the blended surface) at least 5 mm
  // outside every frustum.
  int passed_exact = 0;
  for (const glm::dvec3& q : skeleton_fillets(test::limb_on_trunk(), g.frusta).positions) {
    double outside = 1e300;
    for (const Frustum& f : g.frusta) outside = std::min(outside, frustum_bound(f.shape, q));
    if (outside < 5e-3) continue;
    const Ray ray{q + 3.0 * to_sun, -to_sun};
    if (without.first_hit(ray) < 3 + 1e-3) continue;  // something exact in front of it
    ++passed_exact;
    EXPECT_LE(with.first_hit(ray), 3 + 1e-6) << q.x << ", " << q.y << ", " << q.z;
  }
  EXPECT_GT(passed_exact, 20);
  SunPhotonOptions o;
  o.photons = 200'000;
  o.seed = 5;
  const SunPhotons masked = with.trace(o);
  o.occupancy_mask = false;
  const SunPhotons all = with.trace(o);
  ASSERT_GT(all.vectors.vectors.size(), 1000u);
  expect_same_vectors(all.vectors, masked.vectors, "mask, fillets");
  for (const ShadowVector& v : all.vectors.vectors) ASSERT_LT(v.frustum, g.frusta.size());
}

}  // namespace
}  // namespace sylva
