// Tests for core/cpu/light_tracer.h: the light a sensor sphere receives, against closed
// forms (docs/spec/light.md "Accuracy and cost"): open sky, an opaque disc under a zenith
// sun and under uniform and overcast skies, Beer–Lambert under slabs of random leaves, a sensor on its own twig, the photons
// against the backward gather, and the same answers on any thread count.
#include "core/cpu/light_tracer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/cpu/crotch_tracer.h"
#include "core/geometry/crotch_mesh.h"
#include "core/light/sky.h"
#include "core/scene/light_cases.h"
#include "tests/support/limb_crotch.h"
#include "tests/support/test_scenes.h"

namespace sylva {
namespace {

Scene light_scene(LightSky sky, const glm::dvec3& to_sun = {0, 1, 0}, uint64_t photons = 200'000, double r = 0.1) {
  return light_check_scene(sky, to_sun, 0.01, photons, r);
}

TEST(LightSky, SamplesFollowTheirRadianceAndTheSunShareIsTheScalarOne) {
  // Fraction of directions within 30° and 45° of the zenith (light.md, light-growth notes
  // §4.2 give the horizontal ones; over solid angle UOC is 1 − μ0, SOC 1 − (μ0 + μ0²)/2).
  for (SkyShape shape : {SkyShape::uniform, SkyShape::overcast}) {
    const int n = 200000;
    int within30 = 0;
    for (int i = 0; i < n; ++i) within30 += sky_sample_mu(shape, (i + 0.5) / n) > std::cos(std::numbers::pi / 6);
    const double mu0 = std::cos(std::numbers::pi / 6);
    const double expected = shape == SkyShape::uniform ? 1 - mu0 : 1 - (mu0 + mu0 * mu0) / 2;
    EXPECT_NEAR(within30 / double(n), expected, 1e-4);
  }
  EXPECT_DOUBLE_EQ(sun_scalar_share(1, 0.5, SkyShape::uniform), 1);
  EXPECT_DOUBLE_EQ(sun_scalar_share(0.5, -0.1, SkyShape::uniform), 0);
  // f = 0.5, μs = 0.5: sun 1, sky 0.5·2 = 1 → a half.
  EXPECT_NEAR(sun_scalar_share(0.5, 0.5, SkyShape::uniform), 0.5, 1e-15);
  // SOC: sky 0.5·12/7 → 1/(1 + 6/7) = 7/13.
  EXPECT_NEAR(sun_scalar_share(0.5, 0.5, SkyShape::overcast), 7.0 / 13.0, 1e-15);
}

TEST(LightTracer, OpenSkyGivesOneEverywhereAboveTheGround) {
  const std::vector<glm::dvec3> sensors = {{0, 1, 0}, {3, 2, -1}, {-2, 0.5, 4}, {1, 5, 1}};
  for (LightSky sky : {LightSky::sun, LightSky::uniform, LightSky::overcast, LightSky::sun_overcast}) {
    const Scene s = light_scene(sky, {0.3, 1, 0.2}, 200'000, 0.3);
    LightAnswerStats stats;
    auto a = PhotonLightOracle(2).answer({}, sensors, s, 0, &stats);
    ASSERT_TRUE(a) << a.error().format();
    for (const LightAnswer& x : *a) {
      EXPECT_GT(x.std_error, 0);
      EXPECT_NEAR(x.q, 1.0, 3 * x.std_error) << light_sky_name(sky);
      EXPECT_GT(x.toward.y, 0);
    }
    EXPECT_EQ(stats.photons, 200'000u);
  }
  // The sun's photons come from the sun: the direction is the sun's.
  auto a = PhotonLightOracle(2).answer({}, sensors, light_scene(LightSky::sun, {0.3, 1, 0.2}), 0);
  ASSERT_TRUE(a);
  EXPECT_NEAR(glm::dot((*a)[0].toward, glm::normalize(glm::dvec3(0.3, 1, 0.2))), 1, 1e-6);
}

TEST(LightTracer, AnOpaqueDiscShadesBelowItsCentreAndNotOutsideItsShadow) {
  const std::vector<Skeleton> plants = {light_disc(1.0, 2.0)};
  const std::vector<glm::dvec3> sensors = {{0, 1, 0}, {3, 1, 0}, {0, 3, 0}};
  auto a = PhotonLightOracle(2).answer(plants, sensors, light_scene(LightSky::sun), 0);
  ASSERT_TRUE(a) << a.error().format();
  EXPECT_EQ((*a)[0].q, 0);
  EXPECT_EQ((*a)[0].toward, glm::dvec3(0, 0, 0));
  EXPECT_NEAR((*a)[1].q, 1, 3 * (*a)[1].std_error);
  EXPECT_NEAR((*a)[2].q, 1, 3 * (*a)[2].std_error);
}

TEST(LightTracer, UnderADiscTheSkysClosedFormHoldsForPhotonsAndGather) {
  // 1 m below a disc of radius 1 the disc hides the sky within 45° of the zenith: q is the
  // rest of the sky's light over solid angle — UOC μ0 = 0.7071, SOC (μ0 + μ0²)/2 = 0.6036.
  const std::vector<Skeleton> plants = {light_disc(1.0, 2.0)};
  const std::vector<glm::dvec3> sensors = {{0, 1, 0}};
  for (LightSky sky : {LightSky::uniform, LightSky::overcast}) {
    const double expected = under_disc_q(1, 1, sky == LightSky::overcast);
    const Scene s = light_scene(sky, {0, 1, 0}, 2'000'000, 0.05);
    auto photons = PhotonLightOracle(2).answer(plants, sensors, s, 0);
    auto gather = gather_light(plants, sensors, s, 0, 100'000);
    ASSERT_TRUE(photons && gather);
    const LightAnswer& p = (*photons)[0];
    const LightAnswer& g = (*gather)[0];
    // The sphere's own extent (r = 0.05 m) moves q by under 0.01.
    EXPECT_NEAR(p.q, expected, 3 * p.std_error + 0.01) << light_sky_name(sky);
    EXPECT_NEAR(g.q, expected, 3 * g.std_error) << light_sky_name(sky);
    EXPECT_NEAR(p.q, g.q, 3 * std::hypot(p.std_error, g.std_error) + 0.01);
    // The light comes from all around the disc: by symmetry its mean is straight up.
    EXPECT_NEAR(p.toward.x, 0, 0.15);  // about 5 standard errors at ~2200 crossings
    EXPECT_NEAR(p.toward.z, 0, 0.15);
    EXPECT_NEAR(g.toward.y, 1, 0.01);
  }
}

TEST(LightTracer, UnderASlabOfRandomLeavesBeerLambertHolds) {
  // light.md: q = exp(−0.5 L / cos θ) — 0.6065 and 0.3679 at θ = 0, 0.5614 and 0.3152 at
  // θ = 30° for L = 1 and 2. Sensors (r = 0.5 m) on a 5 × 5 grid 0.5 m below the slab's
  // middle; their mean, within three standard errors of the spread between sensors (the
  // leaves' randomness and the photons' together).
  std::vector<glm::dvec3> sensors;
  for (int i = -2; i <= 2; ++i)
    for (int k = -2; k <= 2; ++k) sensors.push_back({1.2 * i, 0.5, 1.2 * k});
  for (double lai : {1.0, 2.0})
    for (double theta_deg : {0.0, 30.0}) {
      const double theta = theta_deg * std::numbers::pi / 180;
      const std::vector<Skeleton> plants = {leaf_slab(lai, 7 + static_cast<uint64_t>(lai))};
      const Scene s = light_scene(LightSky::sun, {std::sin(theta), std::cos(theta), 0}, 1'000'000, 0.5);
      auto a = PhotonLightOracle(2).answer(plants, sensors, s, 0);
      ASSERT_TRUE(a);
      double sum = 0, sum2 = 0;
      for (const LightAnswer& x : *a) sum += x.q, sum2 += x.q * x.q;
      const double n = static_cast<double>(sensors.size());
      const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / (n - 1));
      const double expected = beer_lambert_q(lai, theta);
      EXPECT_NEAR(mean, expected, 3 * se) << "LAI " << lai << ", sun at " << theta_deg << "°, se " << se;
      EXPECT_LT(se, 0.03);
    }
}

// docs/joints.md "Crotches": where the plants' skin blends its crotches, the `?E` light
// meets the fillets too. Lines through fillet points at least 1 cm outside the exact
// frusta that graze through the crease without meeting either solid (found with the
// accelerator: none of the frusta's boxes, the fillet in front); a sensor 1 m down such a
// line under a point sun along it: where the exact frusta let the whole sensor (its centre
// and four points of its rim) see the sun and the fillet hides all of it, the gather is 1
// without the blend and 0 with it, and the photons agree.
TEST(LightTracer, TheBlendedCrotchesFilletsShadeWhereTheExactFrustaDoNot) {
  const std::vector<Skeleton> plants = {test::limb_on_trunk()};
  const double r = 0.003;
  SkinOptions blended;
  blended.blend_crotches = true;
  SkinOptions unblended;
  unblended.blend_crotches = false;
  const SkinnedSkeleton skinned = skin_skeleton(plants[0], blended);
  const CrotchBalls balls(find_crotches(plants[0], skinned.frusta), skinned.frusta);
  const FrustumAccel exact_accel(skinned.frusta), blended_accel(skinned.frusta, CustomFrusta{}, &balls);
  std::mt19937_64 rng(17);
  std::vector<glm::dvec3> directions;
  while (directions.size() < 300) {
    const glm::dvec3 d = test::random_unit(rng);
    if (d.y > 0.2) directions.push_back(d);
  }
  struct Candidate {
    glm::dvec3 sensor, to_sun;
  };
  std::vector<Candidate> found;
  int lines = 0;
  for (const glm::dvec3& q : skeleton_fillets(plants[0], skinned.frusta).positions) {
    double outside = 1e300;
    for (const Frustum& f : skinned.frusta) outside = std::min(outside, frustum_bound(f.shape, q));
    if (outside < 0.01) continue;
    for (const glm::dvec3& to_sun : directions) {
      const Ray line{q - 1.0 * to_sun, to_sun};
      if (exact_accel.any(line, 0, 10)) continue;  // the exact solids are in the way
      if (!nearest_wood(blended_accel, &balls, line, 0, 10).hit_any()) continue;
      ++lines;
      Scene s = light_scene(LightSky::sun, to_sun, 4'000'000, r);
      s.sun.angular_radius_deg = 0;
      s.ground.height = -10;
      const glm::dvec3 e0 = glm::normalize(glm::cross(to_sun, glm::dvec3(0, 0, 1)));
      const glm::dvec3 e1 = glm::cross(to_sun, e0);
      std::vector<glm::dvec3> points = {line.origin};
      for (const glm::dvec3& d : {e0, -e0, e1, -e1}) points.push_back(line.origin + r * d);
      auto exact = gather_light(plants, points, s, 0, 4, unblended);
      auto blend = gather_light(plants, points, s, 0, 4, blended);
      ASSERT_TRUE(exact && blend);
      bool all = true;
      for (size_t i = 0; i < points.size(); ++i) all = all && (*exact)[i].q == 1 && (*blend)[i].q == 0;
      if (all) found.push_back({line.origin, to_sun});
      break;  // one direction a point
    }
    if (found.size() == 3) break;
  }
  std::printf("[ light ] %d grazing lines through fillet points, %zu sensors shaded whole by the fillet\n", lines,
              found.size());
  ASSERT_EQ(found.size(), 3u);
  for (const Candidate& c : found) {
    Scene s = light_scene(LightSky::sun, c.to_sun, 4'000'000, r);
    s.sun.angular_radius_deg = 0;
    s.ground.height = -10;
    const std::vector<glm::dvec3> sensor = {c.sensor};
    auto exact = PhotonLightOracle(2, unblended).answer(plants, sensor, s, 0);
    auto blend = PhotonLightOracle(2, blended).answer(plants, sensor, s, 0);
    ASSERT_TRUE(exact && blend);
    EXPECT_GT((*exact)[0].q, 0);
    EXPECT_NEAR((*exact)[0].q, 1, 3 * (*exact)[0].std_error);
    EXPECT_EQ((*blend)[0].q, 0);
  }
}

TEST(LightTracer, OneFrustumInterceptsTheSunsIrradianceTimesItsProjectedArea) {
  // A horizontal cylinder of radius a = 5 cm along x, from x = -1.5 to 1.5 m, 1.5 m above
  // the centre of a sensor of radius R = 1 m, under a zenith sun: it takes out of the
  // sensor exactly the light its projected area E·A⊥ intercepts, the strip |z| < a of the
  // beam, whose track through the sphere is ∫ π(R² − z²) dz over |z| < a. So
  // q = 1 − (2πR²a − 2πa³/3) / (4πR³/3) = 1 − 3a/(2R) + a³/(2R³) = 0.9250625.
  Skeleton bar;
  bar.joints = {{{-1.5, 1.5, 0}, 0.05, 0}, {{1.5, 1.5, 0}, 0.05, 0}};
  bar.chains = {{0, 2, std::nullopt}};
  const std::vector<Skeleton> plants = {bar};
  const std::vector<glm::dvec3> sensors = {{0, 0, 0}};
  Scene s = light_scene(LightSky::sun, {0, 1, 0}, 4'000'000, 1.0);
  s.ground.height = -10;
  s.sun.angular_radius_deg = 0;
  auto a = PhotonLightOracle(2).answer(plants, sensors, s, 0);
  ASSERT_TRUE(a);
  const double expected = 1 - 3 * 0.05 / 2 + std::pow(0.05, 3) / 2;
  EXPECT_NEAR((*a)[0].q, expected, 3 * (*a)[0].std_error) << "std error " << (*a)[0].std_error;
  EXPECT_LT((*a)[0].std_error, 0.002);
}

TEST(LightTracer, ASensorIgnoresTheTwigItSitsOnButNotAnother) {
  // A vertical twig from y = 1 to 3 and a sensor on its side; a horizontal branch of
  // radius 0.3 along x at y = 3.5, whose axis passes 0.5 m above a second sensor.
  Skeleton sk = test::cylinder(0.05, 1, 3);
  Skeleton other;
  other.joints = {{{4, 3.5, 0}, 0.3, 0}, {{6, 3.5, 0}, 0.3, 0}};
  other.chains = {{0, 2, std::nullopt}};
  const std::vector<Skeleton> plants = {sk, other};
  const std::vector<glm::dvec3> sensors = {{0.08, 2, 0}, {5, 3, 0}};
  const Scene s = light_scene(LightSky::sun, {0.4, 1, 0}, 400'000, 0.1);
  auto a = PhotonLightOracle(2).answer(plants, sensors, s, 0);
  ASSERT_TRUE(a);
  EXPECT_NEAR((*a)[0].q, 1, 3 * (*a)[0].std_error);
  EXPECT_EQ((*a)[1].q, 0);  // the branch hides the sun's whole disc from the whole sphere
}

TEST(LightTracer, TheSameAnswersOnOneThreadAndOnTwo) {
  const std::vector<Skeleton> plants = {light_disc(0.5, 2.0), test::cylinder(0.1, 0, 2)};
  const std::vector<glm::dvec3> sensors = {{0.2, 1, 0}, {0.6, 1.5, 0.1}, {0, 2.5, 0}};
  const Scene s = light_scene(LightSky::sun_overcast, {0.5, 1, 0.3}, 100'000);
  auto one = PhotonLightOracle(1).answer(plants, sensors, s, 3);
  auto two = PhotonLightOracle(2).answer(plants, sensors, s, 3);
  ASSERT_TRUE(one && two);
  for (size_t i = 0; i < sensors.size(); ++i) {
    EXPECT_EQ((*one)[i].q, (*two)[i].q);
    EXPECT_EQ((*one)[i].toward, (*two)[i].toward);
  }
  // Another step draws other photons.
  auto next = PhotonLightOracle(2).answer(plants, sensors, s, 4);
  ASSERT_TRUE(next);
  EXPECT_NE((*next)[1].q, (*two)[1].q);
}

}  // namespace
}  // namespace sylva
